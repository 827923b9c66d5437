//! Walkers that walk through the scene: a path of timed keys on the ground, the heading
//! along it, and the walk's phase advanced by the distance walked, so that the feet stay
//! planted.
//!
//! **The path.** Keys of time and position (and optionally heading), joined by the same
//! smooth curve as camera paths ([`crate::spline`]); a key next to a segment whose two
//! keys share a position has a zero tangent, so that a walker keyed to stop stands still
//! there instead of overshooting and stepping back. Before the first key a walker stands
//! at it, after the last at the last.
//!
//! **The heading** follows the path's direction of travel (a walker faces `+x` of its
//! subject frame, so heading `h` walks toward `(cos h, 0, −sin h)`), or, when every key
//! gives `heading_deg`, the keyed headings on the same curve (each key turned the short
//! way from the previous). Where the walker stands still it keeps the last direction it
//! walked in.
//!
//! **The phase.** A captured walk moves its stance foot backward at the treadmill's
//! speed `v`: one cycle of the walk covers a stride of `v · cycle` metres. A walker on a
//! path is at phase `offset / cycle + d(t) / stride` (cycles), `d(t)` the distance walked
//! along the path by time `t`, so that its stance foot moves forward with the path as
//! fast as it moves back in the walker's frame: it stays put on the ground. A walker
//! keyed faster or slower than the captured speed plays its walk faster or slower
//! ([`SPEED_RANGE`] says where that stops looking like the captured gait). A path of no
//! length (every key at one place), a walker without a path, and a field that does not
//! know its gait's speed walk on the spot: phase `(t + offset) / cycle`, as before paths.
//!
//! **Turning on the planted foot** ([`Pivot`]). Turned about its root, a walker on a bend
//! would swing the foot it stands on by the turn times the foot's distance from the root
//! (3 cm over a stance on a 90° bend of 3.8 m). Where the field's hulls tell where the
//! feet are on the belt ([`frf_reflectance::gait_speed::FootTrack`]), the walker's root is
//! moved off its path by what keeps the standing foot still as it turns:
//! `ċ = −ω ŷ × R(h) f`, `ω` the heading's rate and `f` the standing foot in the walker's
//! frame, integrated along the path. While both feet are down a rigid turn would move
//! one of them, so the walker does not turn then: it owes the path's turn, and catches up
//! on the next single foot ([`CATCH_UP_S`]), as people turn on one foot, and it goes where
//! it faces (the path's distance, along its own heading), steering back toward its path
//! ([`STEER_M`]). The root stays within a few centimetres of the path and the heading
//! within a few degrees of it.

use std::sync::Arc;

use frf_core::camera::{Camera, Rigid};
use glam::Vec3;

use crate::spline;

/// The fastest a walker may be keyed to move, metres per second: faster than any
/// sprinter (about 12 m/s), so only a mistake (a time or a position off by orders of
/// magnitude) is refused.
pub const MAX_WALK_SPEED_MPS: f64 = 15.0;

/// Speeds, as fractions of the captured gait's, within which a walker's steps are
/// played at a rate a person would take them; beyond, the scene says so. People change
/// both cadence and stride with speed (about equally, near a comfortable walk), so a
/// walk played 25 % faster or slower by cadence alone stays within what walkers do.
pub const SPEED_RANGE: (f64, f64) = (0.75, 1.25);

/// How far from the origin a position may lie, metres (walkers, the viewer's camera):
/// f32 still resolves a millimetre there.
pub const MAX_DISTANCE_M: f32 = 1e4;

/// Samples of each segment of a path for its arc length: the chord of a 1/64 of a
/// segment falls short of the arc by under 0.01 % for the gentlest curves a walker takes
/// (a turn of 90° over a segment), far below a millimetre over a scene's paths.
const ARC_SAMPLES: usize = 64;

/// Paths shorter than this walk on the spot (metres).
const STILL_M: f64 = 1e-6;

/// One key of a walker's path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WalkKey {
    /// Seconds, scene clock.
    pub time: f64,
    /// On the ground (`y = 0`), scene frame, metres.
    pub position: Vec3,
    /// Radians about `+y`, when keyed.
    pub heading: Option<f64>,
}

/// A walker's path (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct WalkPath {
    keys: Vec<WalkKey>,
    times: Vec<f64>,
    /// Keyed headings, unwrapped (each within half a turn of the previous).
    headings: Option<Vec<f64>>,
    /// `(time, distance walked)` at [`ARC_SAMPLES`] points a segment, and the last key.
    arc: Vec<(f64, f64)>,
}

/// How a walk's phase follows time or distance: its cycle, and its stride (metres per
/// cycle) when the field knows its gait's speed.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Gait {
    /// Seconds per cycle.
    pub cycle_seconds: f64,
    /// Metres per cycle (the treadmill's speed times the cycle); `None`: unknown, walkers
    /// walk on the spot.
    pub stride_m: Option<f64>,
}

impl Gait {
    /// A gait of `cycle_seconds` whose speed is `speed_mps` when known.
    pub fn new(cycle_seconds: f64, speed_mps: Option<f64>) -> Self {
        Self {
            cycle_seconds,
            stride_m: speed_mps
                .filter(|v| v.is_finite() && *v > 0.0)
                .map(|v| v * cycle_seconds),
        }
    }

    /// The walk of `field`: its cycle, and its gait's speed as the field records it, or
    /// as its visual hulls tell it ([`frf_reflectance::gait_speed`]); `None` when neither
    /// does (its walkers walk on the spot).
    pub fn of_field<R: frf_reflectance::container::ReadAt>(
        field: &frf_reflectance::FieldFile<R>,
    ) -> crate::Result<Self> {
        let speed = frf_reflectance::gait_speed::gait_speed_mps(field)?;
        Ok(Self::new(field.header().cycle_seconds, speed))
    }

    /// The captured speed, metres per second.
    pub fn speed_mps(&self) -> Option<f64> {
        self.stride_m.map(|s| s / self.cycle_seconds)
    }
}

impl WalkPath {
    /// The path through `keys`: at least two, in strictly increasing time, finite, on the
    /// ground, every key with a heading or none, no faster than [`MAX_WALK_SPEED_MPS`].
    /// A refusal names the key (its index) and the problem.
    pub fn new(keys: Vec<WalkKey>) -> Result<Self, (usize, String)> {
        if keys.len() < 2 {
            return Err((
                0,
                "a path needs at least two keys (a walker standing still gives position \
                 instead)"
                    .into(),
            ));
        }
        for (j, k) in keys.iter().enumerate() {
            if !k.time.is_finite() || !k.position.is_finite() {
                return Err((j, "a value is not finite".into()));
            }
            if k.position.y != 0.0 {
                return Err((j, "walkers walk on the ground: y must be 0".into()));
            }
            if k.position.abs().max_element() > MAX_DISTANCE_M {
                return Err((j, "a position beyond 10 km".into()));
            }
            if j > 0 && k.time <= keys[j - 1].time {
                return Err((
                    j,
                    format!("time {} does not follow {}", k.time, keys[j - 1].time),
                ));
            }
            if k.heading.is_some_and(|h| !h.is_finite()) {
                return Err((j, "heading_deg is not finite".into()));
            }
        }
        let keyed = keys.iter().filter(|k| k.heading.is_some()).count();
        if keyed != 0 && keyed != keys.len() {
            let j = keys.iter().position(|k| k.heading.is_none()).unwrap_or(0);
            return Err((
                j,
                "give heading_deg at every key or at none (then the walker faces where it \
                 walks)"
                    .into(),
            ));
        }
        let headings = (keyed > 0).then(|| {
            let mut out: Vec<f64> = Vec::with_capacity(keys.len());
            for k in &keys {
                let h = k.heading.unwrap_or(0.0);
                out.push(match out.last() {
                    Some(&prev) => {
                        let turn = (h - prev + std::f64::consts::PI)
                            .rem_euclid(std::f64::consts::TAU)
                            - std::f64::consts::PI;
                        prev + turn
                    }
                    None => h,
                });
            }
            out
        });
        let times = keys.iter().map(|k| k.time).collect();
        let mut path = Self {
            keys,
            times,
            headings,
            arc: Vec::new(),
        };
        path.arc = path.arc_table();
        for w in path.arc.windows(2) {
            let speed = (w[1].1 - w[0].1) / (w[1].0 - w[0].0);
            if speed.is_nan() || speed > MAX_WALK_SPEED_MPS {
                let j = path.times.partition_point(|&t| t <= w[0].0).max(1);
                return Err((
                    j,
                    format!(
                        "the walker would move at {speed:.3e} m/s, beyond the {MAX_WALK_SPEED_MPS} m/s \
                         anyone walks or runs: a time or a position is off"
                    ),
                ));
            }
        }
        Ok(path)
    }

    /// The keys.
    pub fn keys(&self) -> &[WalkKey] {
        &self.keys
    }

    /// `(first, last)` key times.
    pub fn span(&self) -> (f64, f64) {
        (self.times[0], self.times[self.times.len() - 1])
    }

    /// Whether the path has no length: the walker walks on the spot.
    pub fn is_still(&self) -> bool {
        self.length_m() < STILL_M
    }

    /// Metres from the first key to the last along the path.
    pub fn length_m(&self) -> f64 {
        self.arc.last().map_or(0.0, |a| a.1)
    }

    /// The tangent at key `j` scaled to a segment of `h` seconds: zero next to a segment
    /// that does not move (a stop), else the curve's.
    fn tangent(&self, j: usize, h: f64) -> Vec3 {
        let p = |k: usize| self.keys[k].position;
        let stop = (j > 0 && p(j - 1) == p(j)) || (j + 1 < self.keys.len() && p(j + 1) == p(j));
        if stop {
            Vec3::ZERO
        } else {
            spline::tangent(&self.times, &p, j, h)
        }
    }

    /// Position and velocity (metres per second) at time `t` (clamped to the span: still
    /// beyond it).
    fn motion(&self, t: f64) -> (Vec3, Vec3) {
        let (i, s, h) = spline::segment(&self.times, t);
        let (p0, p1) = (self.keys[i].position, self.keys[i + 1].position);
        let (m0, m1) = (self.tangent(i, h), self.tangent(i + 1, h));
        let (t0, t1) = self.span();
        let velocity = if t < t0 || t > t1 {
            Vec3::ZERO
        } else {
            spline::hermite_derivative(p0, p1, m0, m1, s) / h as f32
        };
        let mut position = spline::hermite(p0, p1, m0, m1, s);
        // On the ground exactly, whatever the rounding.
        position.y = 0.0;
        (position, velocity)
    }

    /// Where the walker is at time `t`.
    pub fn position(&self, t: f64) -> Vec3 {
        self.motion(t).0
    }

    /// `(time, distance)` samples along the path.
    fn arc_table(&self) -> Vec<(f64, f64)> {
        let mut out = vec![(self.times[0], 0.0)];
        let mut last = self.keys[0].position;
        let mut d = 0.0f64;
        for i in 0..self.keys.len() - 1 {
            let (t0, t1) = (self.times[i], self.times[i + 1]);
            for k in 1..=ARC_SAMPLES {
                let t = if k == ARC_SAMPLES {
                    t1
                } else {
                    t0 + (t1 - t0) * k as f64 / ARC_SAMPLES as f64
                };
                let p = self.position(t);
                d += (p - last).length() as f64;
                last = p;
                out.push((t, d));
            }
        }
        out
    }

    /// The distance walked along the path by time `t`, metres (0 before the first key,
    /// the whole length after the last).
    pub fn distance(&self, t: f64) -> f64 {
        let a = &self.arc;
        if t <= a[0].0 {
            return 0.0;
        }
        let k = a.partition_point(|s| s.0 <= t);
        if k >= a.len() {
            return self.length_m();
        }
        let (lo, hi) = (a[k - 1], a[k]);
        lo.1 + (hi.1 - lo.1) * (t - lo.0) / (hi.0 - lo.0)
    }

    /// The heading at time `t`, radians (see the module docs).
    pub fn heading(&self, t: f64) -> f64 {
        if let Some(h) = &self.headings {
            let value = |k: usize| Vec3::splat(0.0) + Vec3::X * (h[k] - h[0]) as f32;
            return h[0] + spline::catmull_rom(&self.times, &value, t).x as f64;
        }
        let (_, v) = self.motion(t);
        if v.length() > 1e-6 {
            return heading_of(v);
        }
        // Standing: the last direction walked in, else the first it will walk in.
        let a = &self.arc;
        let k = a.partition_point(|s| s.0 <= t).min(a.len() - 1);
        let chord = |j: usize| self.position(a[j + 1].0) - self.position(a[j].0);
        let moved = |j: &usize| chord(*j).length() > 1e-7;
        (0..k)
            .rev()
            .find(moved)
            .or_else(|| (k..a.len() - 1).find(moved))
            .map_or(0.0, |j| heading_of(chord(j)))
    }

    /// The slowest and fastest speeds along the path where the walker moves, metres per
    /// second (`None` for a path of no length).
    pub fn speed_range(&self) -> Option<(f64, f64)> {
        let speeds: Vec<f64> = self
            .arc
            .windows(2)
            .map(|w| (w[1].1 - w[0].1) / (w[1].0 - w[0].0))
            .filter(|&v| v > 1e-3)
            .collect();
        let lo = speeds.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = speeds.iter().copied().fold(0.0, f64::max);
        (!speeds.is_empty()).then_some((lo, hi))
    }
}

/// The heading of a walker moving along `direction` (ground plane): it faces `+x` of its
/// subject frame, which `R_y(h)` turns to `(cos h, 0, −sin h)`.
pub fn heading_of(direction: Vec3) -> f64 {
    (-direction.z as f64).atan2(direction.x as f64)
}

/// Where a walker stands at an instant, and which way it faces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    /// Scene frame, metres, on the ground.
    pub position: Vec3,
    /// About `+y`, radians.
    pub heading: f32,
}

impl Placement {
    /// `world_from_subject = T(position) · R_y(heading)`.
    pub fn world_from_subject(&self) -> Rigid {
        let r = Rigid::rotation_y(self.heading);
        Rigid {
            rotation: r.rotation,
            translation: self.position,
        }
    }

    /// A scene camera as this walker's subject frame sees it.
    pub fn camera_in_subject_frame(&self, camera: &Camera) -> Camera {
        camera.transformed(&self.world_from_subject().inverse())
    }
}

/// How far a walker's root is moved off its path, and its heading off the path's, to turn
/// on its planted foot, along the path's time (see the module docs): offsets on the ground
/// and in heading every [`PIVOT_STEP_S`].
#[derive(Debug, Clone, PartialEq)]
pub struct Pivot {
    start: f64,
    offsets: Vec<(glam::Vec2, f32)>,
}

/// What a walker stands on at an instant ([`Instance::plant`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stance {
    /// The point it turns about, `(x, z)` of its frame.
    pub point: glam::Vec2,
    /// Whether both feet are down (it does not turn then).
    pub both: bool,
}

/// How fast a walker catches up, on one foot, with the turn its path made while both feet
/// were down: the heading it owes decays by e in this many seconds, a quarter of a
/// walk's single support (0.4 s).
pub const CATCH_UP_S: f64 = 0.1;

/// How a walker steers back to its path from where going where it faces took it: toward
/// the point of the path this many metres ahead (a person's look-ahead over two steps).
pub const STEER_M: f64 = 1.0;

/// The step of a [`Pivot`]'s integration, seconds: a 240 Hz clock, where the heading turns
/// by hundredths of a degree.
pub const PIVOT_STEP_S: f64 = 1.0 / 240.0;

impl Pivot {
    /// The offsets `(x, z)` and of heading (radians) at time `t` (held beyond the path's
    /// ends).
    pub fn at(&self, t: f64) -> (glam::Vec2, f32) {
        let f = ((t - self.start) / PIVOT_STEP_S).max(0.0);
        let k = f.floor() as usize;
        let last = self.offsets.len() - 1;
        if k >= last {
            return self.offsets[last];
        }
        let (a, b) = (self.offsets[k], self.offsets[k + 1]);
        let s = (f - k as f64) as f32;
        (a.0.lerp(b.0, s), a.1 + s * (b.1 - a.1))
    }
}

/// One walker of the scene: where it stands (or the path it walks) and how far its walk
/// is ahead of the scene's clock.
#[derive(Debug, Clone, PartialEq)]
pub struct Instance {
    /// Where it stands (scene frame, metres); on a path, the first key's position.
    pub position: Vec3,
    /// Its heading about `+y`, radians; on a path, its heading at the first key.
    pub heading: f32,
    /// Seconds its walk is ahead of the scene's clock (on a path: of its start).
    pub time_offset: f64,
    /// The path it walks, if it moves.
    pub path: Option<Arc<WalkPath>>,
    /// Its root's offsets off the path that turn it on its planted foot, once the field's
    /// feet are known ([`Instance::plant`]).
    pub pivot: Option<Arc<Pivot>>,
}

impl Instance {
    /// A walker standing at `position`, turned by `heading` (radians), its walk
    /// `time_offset` seconds ahead of the scene's clock.
    pub fn standing(position: Vec3, heading: f32, time_offset: f64) -> Self {
        Self {
            position,
            heading,
            time_offset,
            path: None,
            pivot: None,
        }
    }

    /// A walker on `path`, its walk `time_offset` seconds ahead.
    pub fn walking(path: WalkPath, time_offset: f64) -> Self {
        let t0 = path.span().0;
        Self {
            position: path.position(t0),
            heading: path.heading(t0) as f32,
            time_offset,
            path: Some(Arc::new(path)),
            pivot: None,
        }
    }

    /// Turns it on its planted foot as it walks its path: its [`Pivot`] under `gait`,
    /// its feet on the belt as `stance` gives them (seconds into the cycle to the point
    /// `(x, z)` of its frame it stands on, and whether both feet are down; `None` in the
    /// air). Nothing for a walker that does not move or a gait that does not know its
    /// stride.
    pub fn plant(&mut self, gait: &Gait, stance: &dyn Fn(f64) -> Option<Stance>) {
        let Some(path) = self.path.clone().filter(|p| !p.is_still()) else {
            return;
        };
        if gait.stride_m.is_none() {
            return;
        }
        let (t0, t1) = path.span();
        let steps = ((t1 - t0) / PIVOT_STEP_S).ceil() as usize;
        let (mut c, mut lag) = (glam::Vec2::ZERO, 0.0f64);
        let mut offsets = Vec::with_capacity(steps + 1);
        offsets.push((c, 0.0));
        let wrap = |a: f64| {
            (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
        };
        for k in 0..steps {
            let t = t0 + k as f64 * PIVOT_STEP_S;
            let (h0, h1) = (path.heading(t), path.heading(t + PIVOT_STEP_S));
            let path_turn = wrap(h1 - h0);
            let on = stance(self.phase(t + 0.5 * PIVOT_STEP_S, gait) * gait.cycle_seconds);
            // Where it should face: the path's way, steered back toward the path from where
            // going where it faces has taken it ([`STEER_M`]).
            let hp = 0.5 * (h0 + h1);
            let normal = glam::Vec2::new(-hp.sin() as f32, -hp.cos() as f32);
            let aim = -f64::from(c.dot(normal)).atan2(STEER_M);
            // Both feet down: no turn (the path's turn is owed); one: the turn and what is
            // owed, at the rate of [`CATCH_UP_S`]; in the air: all of it.
            let turn = match on {
                Some(Stance { both: true, .. }) => 0.0,
                Some(_) => path_turn + (aim - lag) * (PIVOT_STEP_S / CATCH_UP_S).min(1.0),
                None => path_turn + aim - lag,
            };
            lag += turn - path_turn;
            // The walker goes where it faces: what the path covers this step, along the
            // walker's heading rather than the path's (no difference without a lag).
            let step = (path.distance(t + PIVOT_STEP_S) - path.distance(t)) as f32;
            let (h, hp) = ((hp + lag) as f32, hp as f32);
            c += step * (glam::Vec2::new(h.cos(), -h.sin()) - glam::Vec2::new(hp.cos(), -hp.sin()));
            if let Some(Stance { point: f, .. }) = on {
                // The foot in the scene frame, from the root: R_y(h) (x, 0, z).
                let r = glam::Vec2::new(
                    f.x * h.cos() + f.y * h.sin(),
                    -f.x * h.sin() + f.y * h.cos(),
                );
                // −ω ŷ × (r.x, 0, r.y) over the step: ŷ × (x, 0, z) = (z, 0, −x).
                c -= turn as f32 * glam::Vec2::new(r.y, -r.x);
            }
            offsets.push((c, lag as f32));
        }
        self.pivot = Some(Arc::new(Pivot { start: t0, offsets }));
    }

    /// Where it stands at scene time `t`.
    pub fn at(&self, t: f64) -> Placement {
        match &self.path {
            Some(p) => {
                let (mut position, mut heading) = (p.position(t), p.heading(t) as f32);
                if let Some(pivot) = &self.pivot {
                    let (c, lag) = pivot.at(t);
                    position += glam::Vec3::new(c.x, 0.0, c.y);
                    heading += lag;
                }
                Placement { position, heading }
            }
            None => Placement {
                position: self.position,
                heading: self.heading,
            },
        }
    }

    /// Whether its heading changes over its path (a path that bends, or keyed headings
    /// that differ).
    pub fn turns(&self) -> bool {
        self.path.as_ref().is_some_and(|p| {
            let h0 = p.heading(p.span().0);
            p.arc.iter().any(|&(t, _)| (p.heading(t) - h0).abs() > 1e-9)
        })
    }

    /// Whether it moves through the scene (a path of some length).
    pub fn moves(&self) -> bool {
        self.path.as_ref().is_some_and(|p| !p.is_still())
    }

    /// Where in its walk cycle it is at scene time `t`, in cycles, `[0, 1)`: pose `k` of
    /// `n` per cycle is at phase `k / n` (see the module docs).
    pub fn phase(&self, t: f64, gait: &Gait) -> f64 {
        let cycle = gait.cycle_seconds;
        match (&self.path, gait.stride_m) {
            (Some(p), Some(stride)) if !p.is_still() => {
                (self.time_offset / cycle + p.distance(t) / stride).rem_euclid(1.0)
            }
            _ => ((t + self.time_offset) / cycle).rem_euclid(1.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(time: f64, x: f32, z: f32) -> WalkKey {
        WalkKey {
            time,
            position: Vec3::new(x, 0.0, z),
            heading: None,
        }
    }

    const GAIT: Gait = Gait {
        cycle_seconds: 1.0,
        stride_m: Some(1.2),
    };

    #[test]
    fn a_straight_path_at_constant_speed_advances_the_phase_by_the_distance() {
        let p = WalkPath::new(vec![key(0.0, 0.0, 0.0), key(5.0, 6.0, 0.0)]).unwrap();
        assert!((p.length_m() - 6.0).abs() < 1e-6);
        let w = Instance::walking(p, 0.25);
        for t in [0.0, 1.0, 2.5, 4.9] {
            let at = w.at(t);
            // Along +x at 1.2 m/s, facing +x.
            assert!((at.position.x as f64 - 1.2 * t).abs() < 1e-4, "{t}: {at:?}");
            assert!(at.heading.abs() < 1e-6);
            // One stride a second: the phase runs with time, a quarter cycle ahead.
            let want = (0.25 + t).rem_euclid(1.0);
            assert!((w.phase(t, &GAIT) - want).abs() < 1e-6, "{t}");
        }
        // Before the path starts and after it ends the walker stands at its ends.
        assert_eq!(w.at(-1.0).position, Vec3::ZERO);
        assert!((w.at(9.0).position.x - 6.0).abs() < 1e-5);
        assert!((w.phase(9.0, &GAIT) - (0.25 + 5.0f64).rem_euclid(1.0)).abs() < 1e-6);
    }

    #[test]
    fn keyed_faster_the_walk_plays_faster() {
        let p = WalkPath::new(vec![key(0.0, 0.0, 0.0), key(2.0, 0.0, -3.0)]).unwrap();
        let w = Instance::walking(p, 0.0);
        // 1.5 m/s on a 1.2 m stride: 1.25 cycles a second, walking toward -z: heading 90°.
        assert!((w.phase(0.4, &GAIT) - 0.5).abs() < 1e-5);
        assert!((w.at(1.0).heading - std::f32::consts::FRAC_PI_2).abs() < 1e-5);
        let (lo, hi) = w.path.as_ref().unwrap().speed_range().unwrap();
        assert!(
            (lo - 1.5).abs() < 1e-4 && (hi - 1.5).abs() < 1e-4,
            "{lo} {hi}"
        );
    }

    #[test]
    fn a_path_of_no_length_walks_on_the_spot() {
        let p = WalkPath::new(vec![key(0.0, 1.0, 2.0), key(3.0, 1.0, 2.0)]).unwrap();
        assert!(p.is_still());
        let w = Instance::walking(p, 0.3);
        let standing = Instance::standing(Vec3::new(1.0, 0.0, 2.0), 0.0, 0.3);
        for t in [0.0, 0.7, 1.9, 3.5] {
            assert_eq!(w.at(t), standing.at(t));
            assert_eq!(w.phase(t, &GAIT), standing.phase(t, &GAIT));
        }
    }

    #[test]
    fn a_curve_turns_the_heading_with_the_path_and_keyed_headings_win() {
        // A quarter circle of radius 4 about (0, 0, -4): from the origin toward +x
        // (heading 0) round to (4, 0, -4) toward -z (heading 90°).
        let r = 4.0f32;
        let keys: Vec<WalkKey> = (0..=8)
            .map(|k| {
                let a = k as f32 / 8.0 * std::f32::consts::FRAC_PI_2;
                key(k as f64 * 0.6, r * a.sin(), -r * (1.0 - a.cos()))
            })
            .collect();
        let p = WalkPath::new(keys.clone()).unwrap();
        for k in 0..=8 {
            let want = (k as f64 / 8.0) * std::f64::consts::FRAC_PI_2;
            let got = p.heading(k as f64 * 0.6);
            // The spline's tangent at a key is its neighbours' chord: off the circle's
            // by half the angle between keys at most, at the ends.
            assert!((got - want).abs() < 0.1, "key {k}: {got} vs {want}");
        }
        let mut keyed = keys;
        for (j, k) in keyed.iter_mut().enumerate() {
            k.heading = Some((j as f64 * 10.0).to_radians());
        }
        let p = WalkPath::new(keyed).unwrap();
        assert!((p.heading(0.6 * 3.0) - 30f64.to_radians()).abs() < 1e-6);
    }

    #[test]
    fn a_stop_stands_still_without_stepping_back() {
        let p = WalkPath::new(vec![
            key(0.0, 0.0, 0.0),
            key(2.0, 2.0, 0.0),
            key(3.0, 2.0, 0.0),
            key(5.0, 4.0, 0.0),
        ])
        .unwrap();
        let mut last = -1.0f32;
        for k in 0..=500 {
            let x = p.position(k as f64 * 0.01).x;
            assert!(x >= last - 1e-6, "stepped back at {}", k as f64 * 0.01);
            last = x;
        }
        assert_eq!(p.position(2.5).x, 2.0);
        // Standing, it keeps facing where it walked.
        assert!(p.heading(2.5).abs() < 1e-6);
    }

    /// A treadmill gait of stride 1.05 m a cycle: each foot down 0.6 of the cycle (the
    /// left from phase 0, the right from 0.5), landing 0.315 m ahead of the root and
    /// carried back at the belt's speed, 0.095 m to its side.
    fn foot(side: usize, phase: f64) -> Option<glam::Vec2> {
        let since = (phase - 0.5 * side as f64).rem_euclid(1.0);
        (since < 0.6).then(|| {
            let z = if side == 0 { -0.095 } else { 0.095 };
            glam::Vec2::new((0.315 - 1.05 * since) as f32, z)
        })
    }

    #[test]
    fn on_a_bend_the_planted_foot_stays_put() {
        // A quarter circle of 3.8 m radius at 1.05 m/s.
        let r = 3.8f32;
        let keys: Vec<WalkKey> = (0..=6)
            .map(|k| {
                let a = k as f32 / 6.0 * std::f32::consts::FRAC_PI_2;
                key(f64::from(a * r) / 1.05, r * a.sin(), -r * (1.0 - a.cos()))
            })
            .collect();
        let gait = Gait::new(1.0, Some(1.05));
        let stance = |t: f64| {
            let down: Vec<glam::Vec2> = (0..2).filter_map(|s| foot(s, t)).collect();
            (!down.is_empty()).then(|| Stance {
                point: down.iter().sum::<glam::Vec2>() / down.len() as f32,
                both: down.len() == 2,
            })
        };
        // The most a foot moves on the ground while down, walking the bend.
        let slide = |w: &Instance| {
            let (t0, t1) = w.path.as_ref().unwrap().span();
            let mut worst = 0.0f32;
            let mut planted = [None, None];
            for k in 0..=((t1 - t0) * 480.0) as usize {
                let t = t0 + k as f64 / 480.0;
                let place = w.at(t).world_from_subject();
                for (side, first) in planted.iter_mut().enumerate() {
                    match foot(side, w.phase(t, &gait)) {
                        Some(f) => {
                            let at = place.transform_point(glam::Vec3::new(f.x, 0.0, f.y));
                            worst = worst.max(at.distance(*first.get_or_insert(at)));
                        }
                        None => *first = None,
                    }
                }
            }
            worst
        };
        let path = WalkPath::new(keys).unwrap();
        let mut w = Instance::walking(path.clone(), 0.0);
        let turned_on_the_root = slide(&w);
        w.plant(&gait, &stance);
        let planted = slide(&w);
        assert!(turned_on_the_root > 0.02, "{turned_on_the_root}");
        assert!(planted < 0.002, "slides {planted} m planted");
        // Its root stays near the path, and it faces nearly where the path goes.
        for k in 0..=100 {
            let t = path.span().1 * k as f64 / 100.0;
            let at = w.at(t);
            assert!(at.position.distance(path.position(t)) < 0.1, "{t}: {at:?}");
            assert!((f64::from(at.heading) - path.heading(t)).abs() < 5f64.to_radians());
        }
    }

    #[test]
    fn bad_paths_are_refused_naming_the_key() {
        let one = WalkPath::new(vec![key(0.0, 0.0, 0.0)]).unwrap_err();
        assert!(one.1.contains("at least two keys"), "{one:?}");
        let order = WalkPath::new(vec![key(1.0, 0.0, 0.0), key(0.5, 1.0, 0.0)]).unwrap_err();
        assert_eq!(order.0, 1);
        assert!(order.1.contains("does not follow"), "{order:?}");
        let nan = WalkPath::new(vec![key(0.0, f32::NAN, 0.0), key(1.0, 1.0, 0.0)]).unwrap_err();
        assert_eq!(nan, (0, "a value is not finite".into()));
        let fast = WalkPath::new(vec![key(0.0, 0.0, 0.0), key(1e-3, 100.0, 0.0)]).unwrap_err();
        assert!(fast.1.contains("m/s"), "{fast:?}");
        let mut half = vec![key(0.0, 0.0, 0.0), key(1.0, 1.0, 0.0)];
        half[0].heading = Some(0.0);
        let e = WalkPath::new(half).unwrap_err();
        assert_eq!(e.0, 1);
        let mut up = key(1.0, 1.0, 0.0);
        up.position.y = 0.5;
        let e = WalkPath::new(vec![key(0.0, 0.0, 0.0), up]).unwrap_err();
        assert!(e.1.contains("ground"), "{e:?}");
    }
}
