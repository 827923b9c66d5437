//! A sun: a distant disc of light of a given angular diameter, added to an environment
//! ([`crate::env::EnvMap::with_sun`]) or lighting alone. Its strength is its illuminance
//! `E = ∫ L dω` over the disc (the irradiance it gives a surface facing it), in the
//! environment's units of radiance times steradians, or its radiance `L` (then
//! `E = L · Ω` with `Ω = 2π (1 − cos r)` the disc's solid angle). A map holds the disc in
//! the texels whose centres it covers, or the nearest one when it is smaller than a texel,
//! keeping `E` exact either way.

use glam::Vec3;

use crate::env::EnvMap;
use crate::error::{CoreError, Result};
use crate::image::Rgb;
use crate::light::{SunFault, sun_fault};

/// The widest sun taken, degrees: wider is an area light, not a sun.
pub const MAX_DIAMETER_DEG: f32 = crate::light::MAX_SUN_DIAMETER_DEG;

/// A map's brightest texel is a sun when it is this many times the map's mean radiance
/// ([`Sun::extract`]).
pub const SUN_CONTRAST: f64 = 100.0;

/// Texels around a sun's brightest at this share of its radiance are the sun's.
pub const SUN_SHARE: f32 = 0.1;

/// The real sun's angular diameter, degrees.
pub const SUN_DIAMETER_DEG: f32 = 0.53;

/// A distant disc of light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sun {
    direction: Vec3,
    diameter: f32,
    illuminance: Rgb,
}

impl Sun {
    /// A sun toward `direction` (scene frame, toward the sun; any length but zero) of
    /// angular diameter `diameter_deg` and illuminance `illuminance` (per channel): values
    /// outside what a sun can be are refused naming them.
    pub fn new(direction: Vec3, diameter_deg: f32, illuminance: Rgb) -> Result<Self> {
        if let Some(fault) = sun_fault(direction, diameter_deg, illuminance) {
            let (what, problem) = match fault {
                SunFault::Direction => ("sun direction", format!("{direction} is not a direction")),
                SunFault::Diameter => (
                    "sun angular diameter",
                    format!("{diameter_deg}° is not within (0, {MAX_DIAMETER_DEG}]°"),
                ),
                SunFault::Illuminance => (
                    "sun illuminance",
                    format!("{illuminance:?} is not a finite, non-negative light"),
                ),
            };
            return Err(CoreError::invalid(what, problem));
        }
        // Any finite, non-zero vector names a direction, however short or long: it is
        // scaled to its largest component before it is normalised, so that neither its
        // length's square underflows (a sun found in a dim map) nor overflows (one of
        // 1e20) in 32-bit floats.
        let direction = (direction / direction.abs().max_element()).normalize();
        Ok(Self {
            direction,
            diameter: diameter_deg.to_radians(),
            illuminance,
        })
    }

    /// The solid angle of a disc of angular diameter `diameter_deg`, steradians.
    pub fn solid_angle(diameter_deg: f32) -> f32 {
        let r = 0.5 * diameter_deg.to_radians();
        2.0 * std::f32::consts::PI * (1.0 - r.cos())
    }

    /// Unit direction toward it.
    pub fn direction(&self) -> Vec3 {
        self.direction
    }

    /// Angular radius, radians.
    pub fn radius(&self) -> f32 {
        0.5 * self.diameter
    }

    /// `∫ L dω` over the disc, per channel.
    pub fn illuminance(&self) -> Rgb {
        self.illuminance
    }

    /// The same sun turned by `angle` radians about `+y` (as a yaw turns an environment).
    pub fn rotated(&self, angle: f32) -> Self {
        Self {
            direction: glam::Mat3::from_rotation_y(angle) * self.direction,
            ..*self
        }
    }

    /// `env` with this sun added: its illuminance spread over the texels whose centres
    /// the disc covers (the nearest texel when it covers none), so that the map's
    /// `∫ L dω` grows by exactly the sun's.
    pub fn lit(&self, env: &EnvMap) -> Result<EnvMap> {
        env.with_disc(self.direction, self.radius(), self.illuminance)
    }

    /// The sun baked into `env`, and `env` without it: the texels around the brightest
    /// one above the horizon whose radiance is at least [`SUN_SHARE`] of its, when that
    /// texel is at least [`SUN_CONTRAST`] times the map's mean radiance (a sun, not a
    /// bright sky). Below the horizon a map holds what the ground sends up: a bright spot
    /// there stays in the map (lit through the basis' floor conditions, or replaced by a
    /// ground lit from above, `FloorModel`), and is never a sun. Its
    /// illuminance is what those texels carry above the median of the ring of texels
    /// around them (the sky behind it), which they are set to; its direction the
    /// energy-weighted mean of theirs; its diameter that of a disc of their solid angle.
    /// `None` when the map has no such sun.
    pub fn extract(env: &EnvMap) -> Result<Option<(Sun, EnvMap)>> {
        let img = env.image();
        let (w, h) = img.size();
        let lum = |p: Rgb| crate::image::luminance(p);
        let total: f64 = env.total_light().iter().map(|&c| c as f64).sum::<f64>() / 3.0;
        let mean = total / (4.0 * std::f64::consts::PI);
        // Rows whose texel centres lie above the horizon: a sun is light from the sky.
        let above: Vec<bool> = (0..h)
            .map(|y| env.direction_of(0.0, y as f32).y > 0.0)
            .collect();
        let (peak_i, peak) = img
            .pixels()
            .iter()
            .enumerate()
            .filter(|(i, _)| above[i / w])
            .map(|(i, &p)| (i, lum(p)))
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or((0, 0.0));
        // (A NaN peak is no sun either.)
        if (peak as f64).partial_cmp(&(SUN_CONTRAST * mean)) != Some(std::cmp::Ordering::Greater) {
            return Ok(None);
        }
        // The bright texels connected to the peak (wrapping in azimuth), at the loosest
        // share of the peak that gives a compact region: a glow or a streak around the
        // peak is left to the basis, and the peak's compact core is the sun (none when
        // not even the core is compact).
        let Some((region, inside)) = SHARES
            .iter()
            .map(|&share| bright_region(env, &above, peak_i, share * peak))
            .find(|(region, _)| compact(env, region))
        else {
            return Ok(None);
        };
        // The sky behind it: the median of the texels bordering the region.
        let mut ring: Vec<Rgb> = Vec::new();
        for &i in &region {
            let (x, y) = ((i % w) as i64, (i / w) as i64);
            for (dx, dy) in [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)] {
                let ny = (y + dy).clamp(0, h as i64 - 1) as usize;
                let j = ny * w + (x + dx).rem_euclid(w as i64) as usize;
                if !inside[j] {
                    ring.push(img.pixels()[j]);
                }
            }
        }
        ring.sort_by(|a, b| lum(*a).total_cmp(&lum(*b)));
        let sky = ring.get(ring.len() / 2).copied().unwrap_or([0.0; 3]);
        let mut radiance = img.clone();
        let (mut e, mut omega, mut towards) = ([0.0f64; 3], 0.0f64, glam::DVec3::ZERO);
        for &i in &region {
            let (x, y) = (i % w, i / w);
            let o = env.texel_solid_angle(y) as f64;
            let p = img.pixels()[i];
            let above: Rgb = std::array::from_fn(|c| (p[c] - sky[c]).max(0.0));
            for c in 0..3 {
                e[c] += above[c] as f64 * o;
            }
            omega += o;
            towards += env.direction_of(x as f32, y as f32).as_dvec3() * (lum(above) as f64 * o);
            radiance.set(x, y, sky);
        }
        let diameter = 2.0
            * (1.0 - omega / (2.0 * std::f64::consts::PI))
                .clamp(-1.0, 1.0)
                .acos();
        // Texels no brighter than the sky behind them carry no sun.
        if e.iter().all(|&c| c <= 0.0) || towards == glam::DVec3::ZERO {
            return Ok(None);
        }
        let sun = Sun::new(
            towards.normalize().as_vec3(),
            (diameter as f32).to_degrees().clamp(1e-3, MAX_DIAMETER_DEG),
            // (No more than a map may carry, which rounding could pass.)
            e.map(|c| c.min(crate::env::MAX_TOTAL_LIGHT) as f32),
        )?;
        Ok(Some((sun, env.with_image(radiance)?)))
    }

    /// Up to `most` suns of `env`, brightest first, each found in what the last left
    /// ([`Sun::extract`]), and the map less them (`None` when it holds none): what a
    /// relighting takes out of a map and relights by the normals.
    pub fn extract_all(env: &EnvMap, most: usize) -> Result<(Vec<Sun>, Option<EnvMap>)> {
        let mut suns = Vec::new();
        let mut rest: Option<EnvMap> = None;
        while suns.len() < most {
            let Some((found, less)) = Sun::extract(rest.as_ref().unwrap_or(env))? else {
                break;
            };
            suns.push(found);
            rest = Some(less);
        }
        Ok((suns, rest))
    }

    /// What a sun below the horizon does (`None` above it), for a note to the user: under
    /// a ground floor it lights nothing (the ground hides it); otherwise it is light from
    /// below, which the map's lower hemisphere carries through the basis' floor conditions
    /// ([`Sun::extract`] never takes it for a sun).
    pub fn below_horizon(&self, ground_floor: bool) -> Option<&'static str> {
        (self.direction.y <= 0.0).then_some(if ground_floor {
            "the sun is below the horizon, under the ground floor: it lights nothing"
        } else {
            "the sun is below the horizon: it lights the subject from below as the \
             environment's lower hemisphere does, through the field's floor conditions \
             (no sharp shading or shadow)"
        })
    }

    /// The same sun `k` times as bright.
    pub fn scaled(&self, k: f32) -> Self {
        Self {
            illuminance: self.illuminance.map(|c| c * k.max(0.0)),
            ..*self
        }
    }
}

/// Shares of the peak a sun's texels are tried at, loosest first ([`Sun::extract`]).
const SHARES: [f32; 4] = [SUN_SHARE, 0.2, 0.4, 0.8];

/// How much wider than a disc of its solid angle a region's light may spread and still
/// be a sun ([`compact`]).
const SPREAD: f64 = 1.5;

/// The texels above the horizon (`above`, per row) connected to texel `peak_i` whose
/// luminance is at least `least` (wrapping in azimuth), and which texels they are.
fn bright_region(
    env: &EnvMap,
    above: &[bool],
    peak_i: usize,
    least: f32,
) -> (Vec<usize>, Vec<bool>) {
    let img = env.image();
    let (w, h) = img.size();
    let lum = |p: Rgb| crate::image::luminance(p);
    let mut inside = vec![false; w * h];
    let mut stack = vec![peak_i];
    inside[peak_i] = true;
    let mut region = Vec::new();
    while let Some(i) = stack.pop() {
        region.push(i);
        let (x, y) = ((i % w) as i64, (i / w) as i64);
        for (dx, dy) in [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)] {
            let ny = y + dy;
            if !(0..h as i64).contains(&ny) || !above[ny as usize] {
                continue;
            }
            let j = ny as usize * w + (x + dx).rem_euclid(w as i64) as usize;
            if !inside[j] && lum(img.pixels()[j]) >= least {
                inside[j] = true;
                stack.push(j);
            }
        }
    }
    (region, inside)
}

/// Whether `region`'s light is gathered like a disc's: the angle its light spreads over
/// around its mean direction (from the mean of the cosine to it, `(1 + cos r) / 2` over
/// a uniform disc of radius `r`) is at most [`SPREAD`] times the radius of a disc of its
/// solid angle, plus a texel. A ring, a streak or a broad glow spreads wider.
fn compact(env: &EnvMap, region: &[usize]) -> bool {
    let img = env.image();
    let w = img.width();
    let (mut omega, mut weight, mut towards) = (0.0f64, 0.0f64, glam::DVec3::ZERO);
    for &i in region {
        let o = env.texel_solid_angle(i / w) as f64;
        let l = crate::image::luminance(img.pixels()[i]) as f64 * o;
        omega += o;
        weight += l;
        towards += env.direction_of((i % w) as f32, (i / w) as f32).as_dvec3() * l;
    }
    if weight <= 0.0 {
        return false;
    }
    let area = (1.0 - omega / (2.0 * std::f64::consts::PI))
        .clamp(-1.0, 1.0)
        .acos();
    let spread = (2.0 * towards.length() / weight - 1.0)
        .clamp(-1.0, 1.0)
        .acos();
    let texel = 2.0 * std::f64::consts::PI / w as f64;
    spread <= SPREAD * area + texel
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_suns_are_refused_naming_the_value() {
        let e = |r: Result<Sun>| r.unwrap_err().to_string();
        assert!(e(Sun::new(Vec3::ZERO, 0.5, [1.0; 3])).contains("sun direction"));
        assert!(e(Sun::new(Vec3::Y, 0.0, [1.0; 3])).contains("sun angular diameter"));
        assert!(e(Sun::new(Vec3::Y, 45.0, [1.0; 3])).contains("sun angular diameter"));
        assert!(e(Sun::new(Vec3::Y, 0.5, [f32::NAN; 3])).contains("sun illuminance"));
        assert!(e(Sun::new(Vec3::Y, 0.5, [-1.0; 3])).contains("sun illuminance"));
        let s = Sun::new(Vec3::new(0.0, 2.0, 0.0), 0.5, [1.0; 3]).unwrap();
        assert!((s.direction().length() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn a_sun_adds_its_illuminance_to_a_map_where_it_is() {
        let base = EnvMap::uniform([0.1; 3], 64).rotated(0.7);
        let dir = crate::light::direction_from_azimuth_elevation(1.0, 0.5);
        for diameter in [SUN_DIAMETER_DEG, 5.0] {
            let sun = Sun::new(dir, diameter, [2.0, 1.5, 1.0]).unwrap();
            let lit = sun.lit(&base).unwrap();
            let (a, b) = (base.total_light(), lit.total_light());
            for c in 0..3 {
                let added = b[c] - a[c];
                assert!(
                    (added - sun.illuminance()[c]).abs() < 1e-3,
                    "{diameter}°: {added}"
                );
            }
            // The brightest texel lies toward the sun, within a texel's width.
            let img = lit.image();
            let (i, _) = img
                .pixels()
                .iter()
                .enumerate()
                .max_by(|a, b| a.1[0].total_cmp(&b.1[0]))
                .unwrap();
            let seen = lit.direction_of((i % img.width()) as f32, (i / img.width()) as f32);
            assert!(seen.dot(dir).acos().to_degrees() < 3.0 + diameter);
        }
    }

    /// An overcast sky (its zenith three times its horizon, a grey ground) whose zenith
    /// glows, a Gaussian lobe of `glow_deg` carrying `glow` of the light, with a hot spot
    /// of `spot_deg` carrying `spot` of it, both toward `toward`. 512x256 texels.
    fn overcast(toward: Vec3, glow_deg: f32, glow: f32, spot_deg: f32, spot: f32) -> EnvMap {
        let grid = EnvMap::uniform([0.0; 3], 256);
        let (w, h) = grid.image().size();
        let dirs: Vec<Vec3> = (0..w * h)
            .map(|i| grid.direction_of((i % w) as f32, (i / w) as f32))
            .collect();
        let lobe = |deg: f32| -> Vec<f32> {
            let s = deg.to_radians();
            dirs.iter()
                .map(|d| (-0.5 * (d.dot(toward).clamp(-1.0, 1.0).acos() / s).powi(2)).exp())
                .collect()
        };
        let sky: Vec<f32> = dirs
            .iter()
            .map(|d| {
                if d.y > 0.0 {
                    (1.0 + 2.0 * d.y) / 3.0
                } else {
                    0.2
                }
            })
            .collect();
        let light = |v: &[f32]| -> f32 {
            v.iter()
                .enumerate()
                .map(|(i, x)| x * grid.texel_solid_angle(i / w))
                .sum()
        };
        let (g, hot) = (lobe(glow_deg), lobe(spot_deg));
        let total = light(&sky) / (1.0 - glow - spot);
        let (kg, kh) = (glow * total / light(&g), spot * total / light(&hot));
        let pixels = (0..w * h)
            .map(|i| [sky[i] + kg * g[i] + kh * hot[i]; 3])
            .collect();
        EnvMap::from_image(crate::image::Image::from_vec(w, h, pixels).unwrap()).unwrap()
    }

    /// A bright region far from a disc (an arc of cloud edge 90° long around the zenith,
    /// 300 times the sky, carrying half the light) is not a sun however bright, where a
    /// disc of the same light is (issue 59: a real overcast map's bright zenith was taken
    /// for an 18° disc carrying 45 % of its light, and the walker relit by it lost 8 dB).
    #[test]
    fn a_bright_arc_is_not_taken_for_a_sun_and_a_disc_as_bright_is() {
        let grid = EnvMap::uniform([0.0; 3], 256);
        let (w, h) = grid.image().size();
        let dirs: Vec<Vec3> = (0..w * h)
            .map(|i| grid.direction_of((i % w) as f32, (i / w) as f32))
            .collect();
        let arc = |d: &Vec3| {
            let elevation = d.y.clamp(-1.0, 1.0).asin().to_degrees();
            let azimuth = d.z.atan2(d.x).to_degrees();
            (elevation - 70.0).abs() < 1.5 && (0.0..90.0).contains(&azimuth)
        };
        let disc = |d: &Vec3| d.dot(Vec3::Y) > 4f32.to_radians().cos();
        for (shape, is_sun) in [(&arc as &dyn Fn(&Vec3) -> bool, false), (&disc, true)] {
            let pixels = dirs
                .iter()
                .map(|d| [if shape(d) { 300.0 } else { 1.0 }; 3])
                .collect();
            let map =
                EnvMap::from_image(crate::image::Image::from_vec(w, h, pixels).unwrap()).unwrap();
            assert_eq!(
                Sun::extract(&map).unwrap().is_some(),
                is_sun,
                "sun: {is_sun}"
            );
        }
    }

    #[test]
    fn a_broad_bright_zenith_is_not_taken_for_a_sun_and_a_hot_spot_in_it_is() {
        // Overhead and a little off it: lobes 12° to 20° wide carrying 40-60 % of the
        // light are a bright overcast, relit by the basis, not a point light.
        for (toward, glow_deg, glow) in [
            (Vec3::Y, 15.0, 0.6),
            (
                crate::light::direction_from_azimuth_elevation(0.7, 1.3),
                12.0,
                0.4,
            ),
            (
                crate::light::direction_from_azimuth_elevation(3.0, 1.2),
                20.0,
                0.5,
            ),
        ] {
            let map = overcast(toward, glow_deg, glow, 1.0, 0.0);
            assert!(
                Sun::extract(&map).unwrap().is_none(),
                "a {glow_deg}° glow taken for a sun"
            );
            // A small bright spot where the clouds thin is a sun, found where it is.
            let map = overcast(toward, glow_deg, glow, 1.5, 0.06);
            let (sun, _) = Sun::extract(&map).unwrap().expect("the hot spot is a sun");
            let off = sun
                .direction()
                .dot(toward)
                .clamp(-1.0, 1.0)
                .acos()
                .to_degrees();
            assert!(off < 1.0, "{glow_deg}°: the sun found {off}° from the spot");
        }
    }

    #[test]
    fn the_built_in_sky_s_sun_is_found_and_taken_out_of_it() {
        let sky = EnvMap::sky().rotated(0.4);
        let (sun, rest) = Sun::extract(&sky).unwrap().unwrap();
        let want = crate::light::direction_from_azimuth_elevation(
            60f32.to_radians() + 0.4,
            40f32.to_radians(),
        );
        assert!(
            sun.direction().dot(want).acos().to_degrees() < 1.0,
            "{}",
            sun.direction()
        );
        // The sky's sun is a 4° disc carrying about 70 % of its light.
        assert!(
            (2.0 * sun.radius().to_degrees() - 4.0).abs() < 1.0,
            "{}",
            sun.radius()
        );
        let (before, after) = (sky.total_light(), rest.total_light());
        for c in 0..3 {
            let kept = after[c] + sun.illuminance()[c];
            assert!(
                (kept - before[c]).abs() < 1e-3 * before[c],
                "{c}: {kept} vs {}",
                before[c]
            );
        }
        assert!(
            sun.illuminance()[0] > 0.6 * before[0],
            "{:?}",
            sun.illuminance()
        );
        // What is left has no sun, and a sun put back is found again.
        assert!(Sun::extract(&rest).unwrap().is_none());
        let again = sun.lit(&rest).unwrap();
        let (found, _) = Sun::extract(&again).unwrap().unwrap();
        assert!(found.direction().dot(sun.direction()) > 0.9998);
        assert!(
            (found.illuminance()[0] - sun.illuminance()[0]).abs() < 0.02 * sun.illuminance()[0]
        );
        // A uniform map has none.
        assert!(
            Sun::extract(&EnvMap::uniform([1.0; 3], 32))
                .unwrap()
                .is_none()
        );
    }

    #[test]
    fn suns_from_the_faintest_to_the_brightest_accepted_keep_their_direction() {
        // A sun of 1e20 and above once lost its direction (its length's square overflowed
        // to infinity, the direction normalised to zero: black frames); one found in a
        // dim map was refused as "not a direction" (the square underflowed).
        let dir = crate::light::direction_from_azimuth_elevation(1.0, 0.5);
        for (sky, e) in [(1e-15f32, 1e-12f32), (1e-8, 1e-6), (0.1, 1e20), (0.1, 1e30)] {
            let sun = Sun::new(dir * e, SUN_DIAMETER_DEG, [e; 3]).unwrap();
            assert!(
                sun.direction().distance(dir) < 1e-6,
                "{e}: {}",
                sun.direction()
            );
            let lit = sun.lit(&EnvMap::uniform([sky; 3], 64)).unwrap();
            let (found, rest) = Sun::extract(&lit)
                .unwrap()
                .unwrap_or_else(|| panic!("{e}: no sun found"));
            assert!(
                found.direction().dot(dir) > 0.999,
                "{e}: {}",
                found.direction()
            );
            let ratio = found.illuminance()[0] / e;
            assert!((ratio - 1.0).abs() < 1e-3, "{e}: found {ratio} of it");
            assert!(rest.total_light()[0].is_finite());
        }
    }

    #[test]
    fn a_sun_below_the_horizon_is_not_taken_for_a_sun() {
        let base = EnvMap::uniform([0.1; 3], 64);
        for el in [-5f32, -60.0, -90.0] {
            let dir = crate::light::direction_from_azimuth_elevation(1.0, el.to_radians());
            let lit = Sun::new(dir, SUN_DIAMETER_DEG, [100.0; 3])
                .unwrap()
                .lit(&base)
                .unwrap();
            assert!(Sun::extract(&lit).unwrap().is_none(), "{el}°");
        }
        // One above the horizon is found beside a brighter one below it.
        let below = crate::light::direction_from_azimuth_elevation(1.0, -0.5);
        let up = crate::light::direction_from_azimuth_elevation(-1.0, 0.5);
        let both = Sun::new(up, SUN_DIAMETER_DEG, [50.0; 3])
            .unwrap()
            .lit(
                &Sun::new(below, 2.0, [100.0; 3])
                    .unwrap()
                    .lit(&base)
                    .unwrap(),
            )
            .unwrap();
        let (found, _) = Sun::extract(&both).unwrap().unwrap();
        assert!(found.direction().dot(up) > 0.999);
    }

    #[test]
    fn the_solid_angle_of_the_real_sun() {
        // About 6.8e-5 sr.
        let o = Sun::solid_angle(SUN_DIAMETER_DEG);
        assert!((o - 6.8e-5).abs() < 0.1e-5, "{o}");
    }
}
