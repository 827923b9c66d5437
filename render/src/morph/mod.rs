//! Interpolation between the pre-lit views of a quad of the grid (docs/design.md section
//! 4.2): the solved four-way morph the renderer uses ([`solved`]), the flowed morphs of
//! Einarsson et al. it replaces ([`e06`]), and the simpler interpolations they are all
//! measured against (nearest view, linear blend).
//!
//! A [`Variant`] names one of them with the renderer's refinements; [`shade`] computes
//! the premultiplied RGBA a pixel's ray sees through the quad it crossed.

pub mod e06;
pub mod solved;

use glam::{Vec2, Vec3};

use crate::cylinder::CylinderHit;
use crate::geometry::PoseGeometry;
use crate::resident::ResidentPose;

/// Which interpolation between views, and which of the renderer's refinements it uses.
///
/// Every variant looks rays beyond the grid's rows up through the geometric proxy
/// ([`crate::proxy`]) unless it says otherwise. `FourWay` is the renderer's morph;
/// the others are what it is measured against: `FourWayE06` is the four-way morph of
/// Einarsson et al., `FourWayOcclusion` that morph with an occlusion cue (measured: no
/// gain), `FourWayNoProxy` the solved morph without the proxy (rays beyond the rows
/// read along their direction, the solve started from the quad's fixation depth).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variant {
    /// The vertex of the quad with the largest weight, unwarped.
    Nearest,
    /// The four vertices blended bilinearly, unwarped.
    Linear,
    /// The two-way flowed morph of Einarsson et al. along the nearer row of the quad.
    TwoWay,
    /// The solved four-way morph ([`solved`]).
    FourWay,
    /// The four-way morph of Einarsson et al. ([`e06`]): each image displaced by the
    /// flows into it, read at the output pixel.
    FourWayE06,
    /// Ablation: E06's four-way morph weighing its sources by the consistency of their
    /// flows.
    FourWayOcclusion,
    /// Ablation: the solved morph without the geometric proxy.
    FourWayNoProxy,
}

/// The interpolations proper: what [`Variant`]s compute before the refinements. The
/// discriminant is the interpolation's index in the shaders.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Nearest view.
    Nearest = 0,
    /// Linear blend.
    Linear = 1,
    /// E06's two-way morph.
    TwoWay = 2,
    /// E06's four-way morph.
    FourWayE06 = 3,
    /// The solved four-way morph.
    FourWay = 4,
}

impl Variant {
    /// The interpolations, simplest first, the renderer's last.
    pub const ALL: [Variant; 5] = [
        Variant::Nearest,
        Variant::Linear,
        Variant::TwoWay,
        Variant::FourWayE06,
        Variant::FourWay,
    ];

    /// The four-way morphs' ablations.
    pub const ABLATIONS: [Variant; 2] = [Variant::FourWayOcclusion, Variant::FourWayNoProxy];

    /// Name in reports and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Variant::Nearest => "nearest",
            Variant::Linear => "linear",
            Variant::TwoWay => "twoway",
            Variant::FourWay => "fourway",
            Variant::FourWayE06 => "fourway-e06",
            Variant::FourWayOcclusion => "fourway-occlusion",
            Variant::FourWayNoProxy => "fourway-no-proxy",
        }
    }

    /// The interpolation it computes.
    pub fn kind(self) -> Kind {
        match self {
            Variant::Nearest => Kind::Nearest,
            Variant::Linear => Kind::Linear,
            Variant::TwoWay => Kind::TwoWay,
            Variant::FourWayE06 | Variant::FourWayOcclusion => Kind::FourWayE06,
            Variant::FourWay | Variant::FourWayNoProxy => Kind::FourWay,
        }
    }

    /// Whether rays beyond the grid's rows are looked up through the proxy (and, for
    /// the solved morph, whether the proxy starts its solve).
    pub fn uses_proxy(self) -> bool {
        self != Variant::FourWayNoProxy
    }

    /// Whether the morph weighs its sources by the consistency of their flows.
    pub fn occlusion_aware(self) -> bool {
        self == Variant::FourWayOcclusion
    }

    /// Index of the interpolation in the shaders.
    pub fn index(self) -> u32 {
        self.kind() as u32
    }

    /// The refinements as the shaders' flag bits: 1 proxy, 2 occlusion-aware.
    pub fn flags(self) -> u32 {
        self.uses_proxy() as u32 | (self.occlusion_aware() as u32) << 1
    }
}

/// The premultiplied RGBA that the ray `origin + t dir`, which crossed the cylinder at
/// `hit`, sees through the quad's views by `variant`; `None` where it sees nothing (it
/// points behind the camera it is looked up in).
pub fn shade(
    pose: &ResidentPose,
    hit: &CylinderHit,
    origin: Vec3,
    dir: Vec3,
    variant: Variant,
) -> Option<[f32; 4]> {
    if variant.kind() == Kind::FourWay {
        return solved::shade(pose, hit, origin, dir, variant.uses_proxy());
    }
    let s: Vec2 = e06::source_pixel(&pose.geometry, hit, origin, dir, variant.uses_proxy())?;
    Some(e06::morph(pose, hit, s, variant))
}

/// The views `[A, B, C, D]` of the quad of a hit (`C = A`, `D = B` for a single row).
pub fn quad_views(geometry: &PoseGeometry, hit: &CylinderHit) -> [usize; 4] {
    let view = |u: usize, v: usize| geometry.view(u, v);
    let (u, v) = (hit.u, hit.v);
    let top = if geometry.rows > 1 { v + 1 } else { v };
    [view(u, v), view(u + 1, v), view(u, top), view(u + 1, top)]
}

fn add(acc: &mut [f32; 4], x: [f32; 4], w: f32) {
    for k in 0..4 {
        acc[k] += w * x[k];
    }
}
