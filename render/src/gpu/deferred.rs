//! Dispatches gathered by kind between two submissions and recorded as one compute pass
//! per kind: every pose relit between two frames (a turning light relights a crowd) adds
//! its dispatches to the relight pass, instead of a pass of its own each. [`Gpu::submit`]
//! records them after what the pending encoder already holds (the clears of the
//! relights' peaks) and after the one dispatch that looks every relight's light up on the
//! device ([`super::turn_light`]). Shadows are relit by the frame that draws them, every
//! walker's in one dispatch ([`super::shadow`]).

use super::Gpu;
use super::timing::compute_pass_writes;

/// The kinds, in the order they are recorded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Kind {
    /// The relighting pass (its sums, then its encoding), [`super::relight`].
    Relight,
}

impl Kind {
    const ALL: [Kind; 1] = [Kind::Relight];

    /// The pass's name (in the timings).
    fn name(self) -> &'static str {
        match self {
            Kind::Relight => "relight",
        }
    }
}

/// One dispatch: its pipeline, its bind group (group 0) and its workgroups.
pub(super) struct Dispatch {
    pub pipeline: wgpu::ComputePipeline,
    pub bind: wgpu::BindGroup,
    pub groups: [u32; 3],
}

/// The dispatches gathered since the last submission, by kind, in the order added.
#[derive(Default)]
pub(super) struct Deferred {
    dispatches: Vec<(Kind, Dispatch)>,
}

impl Gpu {
    /// Adds `dispatches` of `kind` (in order) to the next submission.
    pub(super) fn defer(&self, kind: Kind, dispatches: impl IntoIterator<Item = Dispatch>) {
        let mut deferred = self.deferred.lock().unwrap_or_else(|e| e.into_inner());
        deferred
            .dispatches
            .extend(dispatches.into_iter().map(|d| (kind, d)));
    }

    /// Records the dispatches gathered (one pass per kind that has any) into `encoder`,
    /// made when there is none; none gathered: `encoder` as it was.
    pub(super) fn record_deferred(
        &self,
        encoder: Option<wgpu::CommandEncoder>,
    ) -> Option<wgpu::CommandEncoder> {
        let gathered = std::mem::take(
            &mut self
                .deferred
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .dispatches,
        );
        if gathered.is_empty() {
            return encoder;
        }
        let mut encoder = encoder.unwrap_or_else(|| self.pending_encoder());
        for kind in Kind::ALL {
            let mut of_kind = gathered.iter().filter(|(k, _)| *k == kind).peekable();
            if of_kind.peek().is_none() {
                continue;
            }
            self.dispatched(
                kind.name(),
                gathered.iter().filter(|(k, _)| *k == kind).count(),
            );
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(kind.name()),
                timestamp_writes: compute_pass_writes(self.pass_timestamps(kind.name(), None)),
            });
            for (_, d) in of_kind {
                pass.set_pipeline(&d.pipeline);
                pass.set_bind_group(0, &d.bind, &[]);
                let [x, y, z] = d.groups;
                pass.dispatch_workgroups(x, y, z);
            }
        }
        Some(encoder)
    }
}
