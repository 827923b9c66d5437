//! A plan told: as JSON (`frf render --plan --json`, [`PlanReport`]), as text for a
//! person ([`Plan::describe`]), and where the ground's shadow of a shot comes from, in
//! words ([`shadow_words`]).

use frf_reflectance::FieldHeader;
use frf_render::footprint::SubjectBounds;
use serde::Serialize;

use crate::plan::{Plan, PlanCounts, WalkerCounts};
use crate::{Scene, ShadowSpec};

/// The report of `--plan --json`.
#[derive(Serialize)]
pub struct PlanReport<'a> {
    /// What the plan reads, of what the field holds.
    #[serde(flatten)]
    pub counts: &'a PlanCounts,
    /// Frames planned.
    pub frames: usize,
    /// The poses drawn.
    pub poses: Vec<u32>,
    /// Per pose of `poses`: where its subject can show (the views read are those of the
    /// rays through these bounds).
    pub bounds: Vec<SubjectBounds>,
    /// `(wanted, held)`: a pose the field lacks and the one that stands in for it.
    pub poses_substituted: &'a [(u32, u32)],
    /// Basis conditions not relit.
    pub conditions_left_out: &'a [String],
    /// Of those, the floor's.
    pub floor_conditions_left_out: usize,
    /// Some frame sees the ground patch.
    pub ground_seen: bool,
    /// Some pose's shadow maps are read.
    pub shadow_maps_read: bool,
    /// Per walker: the poses it draws and the views and flows its own rays reach (what
    /// it is made resident with).
    pub walker_counts: &'a [WalkerCounts],
}

impl Plan {
    /// The plan as `--plan --json` reports it.
    pub fn report(&self) -> PlanReport<'_> {
        PlanReport {
            counts: &self.counts,
            frames: self.frames.len(),
            poses: self.poses.iter().map(|p| p.pose).collect(),
            bounds: self.poses.iter().map(|p| p.bounds).collect(),
            poses_substituted: &self.poses_substituted,
            conditions_left_out: &self.conditions_left_out,
            floor_conditions_left_out: self.floor_conditions_left_out,
            ground_seen: self.ground_seen,
            shadow_maps_read: self.poses.iter().any(|p| p.shadow_maps),
            walker_counts: &self.walker_counts,
        }
    }

    /// The plan for a person, a line each: what it reads of what the field holds, the
    /// shadow maps, the walkers' shares and the poses substituted.
    pub fn describe(&self) -> String {
        let c = &self.counts;
        let mb = |b: u64| b as f64 / 1e6;
        let mut lines = vec![
            format!("plan of {} frames:", self.frames.len()),
            format!("  poses      {:>6} of {:>6}", c.poses_used, c.poses_total),
            format!(
                "  views      {:>6} of {:>6}  (over the poses used)",
                c.views_used, c.views_total
            ),
            format!("  flows      {:>6} of {:>6}", c.flows_used, c.flows_total),
            format!(
                "  conditions {:>6} of {:>6}  (left out: {})",
                c.conditions_used,
                c.conditions_total,
                if self.conditions_left_out.is_empty() {
                    "none".to_string()
                } else {
                    self.conditions_left_out.join(", ")
                }
            ),
            format!(
                "  bytes read {:>9.2} of {:>9.2} MB",
                mb(c.bytes_read),
                mb(c.bytes_total)
            ),
            format!(
                "  shadow maps {}",
                if self.poses.iter().any(|p| p.shadow_maps) {
                    "read"
                } else if self.ground_seen {
                    "not read (no maps asked for)"
                } else {
                    "not read (no frame sees the ground patch)"
                }
            ),
        ];
        if self.walker_counts.len() > 1 {
            // Each walker is made resident with what its own rays reach.
            let views: Vec<usize> = self.walker_counts.iter().map(|w| w.views).collect();
            lines.push(format!(
                "  per walker  {} walkers, views made resident {} to {} (mean {:.1}) over their poses",
                views.len(),
                views.iter().min().copied().unwrap_or(0),
                views.iter().max().copied().unwrap_or(0),
                views.iter().sum::<usize>() as f64 / views.len() as f64
            ));
        }
        for (wanted, held) in &self.poses_substituted {
            lines.push(format!(
                "  pose {wanted} is not in the field: pose {held} stands in for it"
            ));
        }
        lines.join("\n")
    }
}

/// Where the ground's shadow of `scene` on the field of `header` comes from under
/// `plan`, in words for a render's summary (`traced_lights`: the lights a traced shadow
/// is cast by).
pub fn shadow_words(
    scene: &Scene,
    plan: &Plan,
    header: &FieldHeader,
    traced_lights: usize,
) -> String {
    let (has_maps, has_hull) = (header.shadows.is_some(), header.hulls.is_some());
    // What a shadow of the other kind would need, said only where the field holds it.
    let other = if has_hull {
        "--shadow traced traces the hull"
    } else {
        "nor has it a visual hull to trace: ingest without --no-shadows to cast a shadow"
    };
    match scene.shadow {
        ShadowSpec::None => "none (--shadow none)".into(),
        // Without maps or a hull there is no shadow to draw: say why first.
        ShadowSpec::Maps if !has_maps => {
            format!("none (the field has no shadow maps, e.g. ingested with --no-shadows; {other})")
        }
        ShadowSpec::Traced if !has_hull => "none (the field has no visual hull to trace, e.g. \
             ingested with --no-shadows: ingest without it to cast a shadow)"
            .into(),
        _ if !plan.ground_seen => "none drawn (no frame sees the ground patch)".into(),
        ShadowSpec::Maps if plan.poses.iter().any(|p| p.shadow_maps) => {
            "relit from the pose's maps".into()
        }
        ShadowSpec::Maps => format!("none (the field has no shadow maps; {other})"),
        ShadowSpec::Traced => {
            format!("traced from the hull under {traced_lights} median-cut lights")
        }
    }
}
