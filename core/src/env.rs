//! HDR lighting environments in latitude–longitude layout, with the USC ICT light-probe
//! mapping (`docs/data.md`): for a unit direction `(x, y, z)` with `y` up,
//! `u = (1 + atan2(x, -z) / π) / 2`, `v = acos(y) / π`; the image centre looks toward
//! `-z`. A yaw (rotation about `+y`, radians, right-handed) turns the whole map:
//! the map's direction `d` lights the subject from `R_y(yaw) d`.
//!
//! Input rule: non-finite texels (NaN, infinity) make the file invalid and are refused
//! with their position; negative texels (which some EXR writers produce from filtering)
//! are clamped to zero and counted in [`EnvMap::clamped_texels`].
//!
//! [`EnvMap::median_cut`] reduces the map to `n` distant lights of nearly equal energy
//! (Debevec, "A median cut algorithm for light probe sampling", SIGGRAPH 2005 poster),
//! keeping the total light exactly: a small, very bright sun ends up alone in its region.
//!
//! [`EnvSource`] is what a user names as lighting (a file, the built-in sky, a uniform
//! white furnace, or none), parsed once where it is read.

use std::collections::BinaryHeap;
use std::f32::consts::PI;
use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use glam::{Mat3, Vec2, Vec3};

use crate::error::{CoreError, Result};
use crate::image::{Border, Image, Rgb, RgbImage, luminance};
use crate::light::DirLight;
use crate::sh::{SH_COUNT, ShLight, sh_basis};

pub use crate::light::MAX_TOTAL_LIGHT;

/// Rows of the map an L2 light becomes: its finest detail is a band-2 lobe, 60° wide.
pub const SH_MAP_HEIGHT: usize = 128;

/// The fewest rows (and half the fewest columns) a map read from a file is integrated
/// at. Every integral over a map (its light, its L2 projection, the lighting conditions')
/// takes each texel's radiance at its centre times its solid angle: exact for the light
/// itself, but for what varies over a texel (a direction, the basis's lobes) only as
/// fine as the texels. A smaller map (a 1x1 uniform light, a 4x2 sky) is read as the
/// same piecewise-constant light on a finer grid, each texel's region split into equal
/// parts of its radiance, so those integrals are within 0.1 % of exact (a uniform 1x1
/// map's L2 light was 9 times its energy, band 1 and 2 as bright as band 0).
pub const MIN_MAP_ROWS: usize = 32;

/// `img` with each texel split into equal parts of its radiance until it has at least
/// [`MIN_MAP_ROWS`] rows and twice as many columns (a larger map as it is).
fn split_small_texels(img: RgbImage) -> RgbImage {
    let (w, h) = img.size();
    if w == 0 || h == 0 || (h >= MIN_MAP_ROWS && w >= 2 * MIN_MAP_ROWS) {
        return img;
    }
    let (fx, fy) = ((2 * MIN_MAP_ROWS).div_ceil(w), MIN_MAP_ROWS.div_ceil(h));
    Image::from_fn(w * fx, h * fy, |x, y| img.get(x / fx, y / fy))
}

/// A latitude–longitude HDR environment of radiance.
#[derive(Debug, Clone)]
pub struct EnvMap {
    radiance: RgbImage,
    yaw: f32,
    clamped_texels: usize,
}

impl EnvMap {
    /// Loads a `.hdr` (Radiance RGBE) or `.exr` map (an 8-bit image is refused,
    /// [`crate::io::read_hdr_rgb`]); a map whose every texel is zero or negative is
    /// refused too: it lights nothing (`none` shows a field unlit). A `.json` file is an
    /// L2 light ([`crate::sh::ShLight`], what `frf env-sh` writes), made a map of
    /// [`SH_MAP_HEIGHT`] rows with its negative lobes kept (the band-limited light a
    /// player relights by, exactly).
    pub fn load(path: &Path) -> Result<Self> {
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"))
        {
            // Its suns (`frf env-sh --suns`) painted into the L2 light's map.
            let (sh, suns) = crate::sh::ShLight::load_with_suns(path)?;
            let mut map = Self::from_sh(&sh, SH_MAP_HEIGHT)?;
            for s in suns {
                let radius = 0.5 * s.diameter_deg.to_radians();
                map = map.with_disc(Vec3::from(s.direction).normalize(), radius, s.illuminance)?;
            }
            return Ok(map);
        }
        let img = crate::io::read_hdr_rgb(path)?;
        let most_negative =
            (img.pixels().iter().flatten()).fold(0.0f32, |m, &c| if c < m { c } else { m });
        let env = Self::from_image(img).map_err(|e| match e {
            CoreError::InvalidArgument { problem, .. } => CoreError::bad_file(path, problem),
            other => other,
        })?;
        if env
            .radiance
            .pixels()
            .iter()
            .all(|p| p.iter().all(|&c| c <= 0.0))
        {
            return Err(CoreError::bad_file(
                path,
                format!(
                    "every texel is zero or negative ({} clamped to zero): the environment lights nothing",
                    env.clamped_texels
                ),
            ));
        }
        if env.clamped_texels > 0 {
            eprintln!(
                "warning: {}: {} texels with a negative value (the most negative {most_negative:.3e}) \
                 clamped to zero",
                path.display(),
                env.clamped_texels
            );
        }
        let env = Self {
            radiance: split_small_texels(env.radiance),
            ..env
        };
        // Relighting sums radiance × solid angle × reflectance in 32-bit floats: a map
        // whose total light nears f32's range (a Radiance exponent near 255) would
        // overflow there to infinite or black pixels.
        let total = env.total_light_f64();
        if let Some(c) = total.iter().position(|&t| t > MAX_TOTAL_LIGHT) {
            return Err(CoreError::bad_file(
                path,
                format!(
                    "its total light ({:.1e} in channel {c}) is beyond what relighting can sum \
                     in 32-bit floats (at most {MAX_TOTAL_LIGHT:.0e}): scale the map down",
                    total[c]
                ),
            ));
        }
        Ok(env)
    }

    /// Wraps a radiance image (width should be twice the height, but any size of at least
    /// 1x1 is accepted). Non-finite texels are refused, negative ones clamped to zero.
    pub fn from_image(radiance: RgbImage) -> Result<Self> {
        let mut env = Self::signed(radiance)?;
        for p in env.radiance.pixels_mut() {
            if p.iter().any(|&c| c < 0.0) {
                env.clamped_texels += 1;
                *p = p.map(|c| c.max(0.0));
            }
        }
        Ok(env)
    }

    /// Wraps an image with its negative texels kept: a light with negative lobes (an L2
    /// light, [`EnvMap::from_sh`]) or a function on the sphere to integrate over the
    /// basis's regions (an SH basis function); non-finite texels are refused.
    pub fn signed(radiance: RgbImage) -> Result<Self> {
        if radiance.width() == 0 || radiance.height() == 0 {
            return Err(CoreError::invalid("environment", "empty image"));
        }
        let w = radiance.width();
        if let Some(i) = radiance
            .pixels()
            .iter()
            .position(|p| p.iter().any(|c| !c.is_finite()))
        {
            return Err(CoreError::invalid(
                "environment",
                format!("texel ({}, {}) is not finite", i % w, i / w),
            ));
        }
        Ok(Self {
            radiance,
            yaw: 0.0,
            clamped_texels: 0,
        })
    }

    /// The map with a distant disc of light added (a sun: unit `direction` toward it,
    /// angular `radius` in radians, `∫ L dω` over it `illuminance`): its illuminance spread
    /// over the texels whose centres the disc covers (the nearest texel when it covers
    /// none), so that the map's `∫ L dω` grows by exactly the disc's. Its other texels are
    /// kept as they are, negative ones too.
    pub fn with_disc(&self, direction: Vec3, radius: f32, illuminance: Rgb) -> Result<Self> {
        let (w, h) = self.image().size();
        let at = self.texel_of(direction);
        let row = (at.y.round().max(0.0) as usize).min(h - 1);
        // Rows within the disc's radius of its centre, and a texel's margin.
        let reach = (radius / (PI / h as f32)).ceil() as usize + 1;
        let cos_r = radius.cos();
        let mut covered: Vec<(usize, usize)> = Vec::new();
        for y in row.saturating_sub(reach)..(row + reach + 1).min(h) {
            for x in 0..w {
                if self.direction_of(x as f32, y as f32).dot(direction) >= cos_r {
                    covered.push((x, y));
                }
            }
        }
        if covered.is_empty() {
            covered.push(((at.x.round() as i64).rem_euclid(w as i64) as usize, row));
        }
        let omega: f32 = covered
            .iter()
            .map(|&(_, y)| self.texel_solid_angle(y))
            .sum();
        let add = illuminance.map(|e| e / omega);
        let mut radiance = self.image().clone();
        for (x, y) in covered {
            let p = radiance.get(x, y);
            radiance.set(x, y, [p[0] + add[0], p[1] + add[1], p[2] + add[2]]);
        }
        self.with_image(radiance)
    }

    /// This map with its texels replaced by `radiance` (of its size), its yaw kept and its
    /// negative texels kept as they are: a signed map (an L2 light's, with its negative
    /// lobes) stays the light a player relights by, not that light clamped. What
    /// [`EnvMap::with_disc`] and [`crate::sun::Sun::extract`] make of a map.
    pub fn with_image(&self, radiance: RgbImage) -> Result<Self> {
        let mut out = EnvMap::signed(radiance)?;
        out.clamped_texels = self.clamped_texels;
        Ok(out.rotated(self.yaw()))
    }

    /// The projection of the map (its yaw included) onto the L2 basis ([`crate::sh`]):
    /// `c_i = ∫ L Y_i dω`, summed over its texels in f64.
    pub fn to_sh(&self) -> ShLight {
        let mut sum = [[0.0f64; 3]; SH_COUNT];
        for y in 0..self.radiance.height() {
            let omega = self.texel_solid_angle(y) as f64;
            for (x, l) in self.radiance.row(y).iter().enumerate() {
                let basis = sh_basis(self.direction_of(x as f32, y as f32));
                for (s, b) in sum.iter_mut().zip(basis) {
                    for c in 0..3 {
                        s[c] += l[c] as f64 * b as f64 * omega;
                    }
                }
            }
        }
        ShLight::from_coefficients(sum.map(|s| s.map(|v| v as f32)))
    }

    /// An L2 light as a `2h x h` map with its negative lobes kept ([`EnvMap::signed`]):
    /// the band-limited light itself, which relighting by the basis reproduces exactly as
    /// a player's `Σ c_i T_i` does. What `--env SH.json` renders.
    pub fn from_sh(sh: &ShLight, h: usize) -> Result<Self> {
        Self::signed(Self::sh_image(sh, h))
    }

    /// [`EnvMap::from_sh`] with the negative texels (the ringing opposite a bright
    /// source) clamped to zero and counted ([`EnvMap::clamped_texels`]).
    pub fn from_sh_clamped(sh: &ShLight, h: usize) -> Result<Self> {
        Self::from_image(Self::sh_image(sh, h))
    }

    fn sh_image(sh: &ShLight, h: usize) -> RgbImage {
        let h = h.max(2);
        let probe = Self::uniform([0.0; 3], h);
        Image::from_fn(2 * h, h, |x, y| {
            sh.radiance(probe.direction_of(x as f32, y as f32))
        })
    }

    /// A constant environment of radiance `value` on a `2n x n` grid.
    pub fn uniform(value: Rgb, n: usize) -> Self {
        Self {
            radiance: Image::new(2 * n.max(1), n.max(1), value),
            yaw: 0.0,
            clamped_texels: 0,
        }
    }

    /// A built-in outdoor environment (no file needed): a sky brightening toward the
    /// horizon, a small sun 40° high at azimuth 60° carrying about 70 % of the light (a
    /// clear day's share), and a brown ground. 256x128 texels.
    pub fn sky() -> Self {
        let probe = Self::uniform([0.0; 3], 128);
        let sun =
            crate::light::direction_from_azimuth_elevation(60f32.to_radians(), 40f32.to_radians());
        // Sun disc of 2° radius (wider than the real 0.27° so that the 1.4° texels resolve it).
        let sun_cos = 2f32.to_radians().cos();
        let radiance = Image::from_fn(256, 128, |x, y| {
            let d = probe.direction_of(x as f32, y as f32);
            if d.dot(sun) > sun_cos {
                [3000.0, 2800.0, 2500.0]
            } else if d.y >= 0.0 {
                let t = 1.0 - d.y;
                [0.35 + 0.5 * t, 0.55 + 0.4 * t, 1.0 + 0.1 * t]
            } else {
                [0.25, 0.18, 0.12]
            }
        });
        Self {
            radiance,
            yaw: 0.0,
            clamped_texels: 0,
        }
    }

    /// The same environment turned by an extra `angle` radians about `+y`.
    pub fn rotated(&self, angle: f32) -> Self {
        Self {
            yaw: self.yaw + angle,
            ..self.clone()
        }
    }

    /// The same environment with its radiance scaled by `k` (at least 0).
    pub fn scaled(&self, k: f32) -> Self {
        Self {
            radiance: self.radiance.map(|p| p.map(|c| c * k.max(0.0))),
            ..self.clone()
        }
    }

    /// A weighted mix of environments (each with its own yaw), resampled to the first
    /// one's texels (bilinear), with no yaw of its own: the light of a cross-fade. Empty
    /// weights give the first map unweighted.
    pub fn mix(maps: &[(&EnvMap, f32)]) -> Result<Self> {
        let Some(&(first, _)) = maps.first() else {
            return Err(CoreError::invalid("environment mix", "no environment"));
        };
        let (w, h) = first.radiance.size();
        let blank = Self {
            radiance: Image::new(w, h, [0.0; 3]),
            yaw: 0.0,
            clamped_texels: 0,
        };
        let radiance = Image::from_fn(w, h, |x, y| {
            let d = blank.direction_of(x as f32, y as f32);
            let mut out = [0.0f32; 3];
            for (map, weight) in maps {
                let l = map.radiance(d);
                for c in 0..3 {
                    out[c] += weight * l[c];
                }
            }
            out
        });
        Ok(Self {
            radiance,
            yaw: 0.0,
            clamped_texels: maps.iter().map(|m| m.0.clamped_texels).sum(),
        })
    }

    /// The current yaw, radians.
    pub fn yaw(&self) -> f32 {
        self.yaw
    }

    /// Texels whose negative channels were clamped to zero on load.
    pub fn clamped_texels(&self) -> usize {
        self.clamped_texels
    }

    /// The radiance image (map frame, before yaw).
    pub fn image(&self) -> &RgbImage {
        &self.radiance
    }

    /// Unit direction (after yaw) of continuous texel coordinates (centres at integers).
    pub fn direction_of(&self, x: f32, y: f32) -> Vec3 {
        let (w, h) = self.radiance.size();
        let u = (x + 0.5) / w as f32;
        let v = (y + 0.5) / h as f32;
        let phi = (2.0 * u - 1.0) * PI;
        let theta = v * PI;
        let d = Vec3::new(
            theta.sin() * phi.sin(),
            theta.cos(),
            -theta.sin() * phi.cos(),
        );
        Mat3::from_rotation_y(self.yaw) * d
    }

    /// Continuous texel coordinates of a direction (after yaw).
    pub fn texel_of(&self, direction: Vec3) -> Vec2 {
        let d = (Mat3::from_rotation_y(-self.yaw) * direction).normalize_or_zero();
        let (w, h) = self.radiance.size();
        let u = (1.0 + d.x.atan2(-d.z) / PI) / 2.0;
        let v = d.y.clamp(-1.0, 1.0).acos() / PI;
        Vec2::new(u * w as f32 - 0.5, v * h as f32 - 0.5)
    }

    /// Radiance arriving from `direction` (bilinear, wrapping in azimuth).
    pub fn radiance(&self, direction: Vec3) -> Rgb {
        let t = self.texel_of(direction);
        let w = self.radiance.width() as f32;
        let x = t.x.rem_euclid(w);
        // Wrap by sampling the two columns explicitly when between the last and first.
        if x > w - 1.0 {
            let f = x - (w - 1.0);
            let a = self.radiance.sample_bilinear(w - 1.0, t.y, Border::Clamp);
            let b = self.radiance.sample_bilinear(0.0, t.y, Border::Clamp);
            return [0, 1, 2].map(|c| a[c] * (1.0 - f) + b[c] * f);
        }
        self.radiance.sample_bilinear(x, t.y, Border::Clamp)
    }

    /// The same light averaged over coarser texels, `width x height` (each the
    /// solid-angle-weighted mean of the texels whose centres fall in it), its yaw kept:
    /// what a light standing for a patch of the sphere sees, not the texel its centre
    /// falls on.
    pub fn coarse(&self, width: usize, height: usize) -> Self {
        let (w, h) = self.radiance.size();
        let (width, height) = (width.clamp(1, w), height.clamp(1, h));
        let mut sum = vec![[0.0f64; 4]; width * height];
        for y in 0..h {
            let (omega, ty) = (self.texel_solid_angle(y) as f64, y * height / h);
            for x in 0..w {
                let cell = &mut sum[ty * width + x * width / w];
                let p = self.radiance.get(x, y);
                for c in 0..3 {
                    cell[c] += p[c] as f64 * omega;
                }
                cell[3] += omega;
            }
        }
        let pixels = sum
            .iter()
            .map(|s| {
                let o = s[3].max(f64::MIN_POSITIVE);
                [0, 1, 2].map(|c| (s[c] / o) as f32)
            })
            .collect();
        Self {
            radiance: Image::from_vec(width, height, pixels).expect("sized above"),
            yaw: self.yaw,
            clamped_texels: self.clamped_texels,
        }
    }

    /// Solid angle of one texel of row `row`, steradians.
    pub fn texel_solid_angle(&self, row: usize) -> f32 {
        let (w, h) = self.radiance.size();
        let top = row as f32 * PI / h as f32;
        let bottom = (row + 1) as f32 * PI / h as f32;
        (2.0 * PI / w as f32) * (top.cos() - bottom.cos())
    }

    /// `∫ L dω` over the whole sphere, per channel.
    pub fn total_light(&self) -> Rgb {
        self.total_light_f64().map(|v| v as f32)
    }

    /// [`EnvMap::total_light`] summed and kept in f64 (it may exceed f32's range).
    fn total_light_f64(&self) -> [f64; 3] {
        let mut sum = [0.0f64; 3];
        for y in 0..self.radiance.height() {
            let omega = self.texel_solid_angle(y) as f64;
            for p in self.radiance.row(y) {
                for c in 0..3 {
                    sum[c] += p[c] as f64 * omega;
                }
            }
        }
        sum
    }

    /// Irradiance on an unshadowed horizontal surface facing up, `∫_{upper} L cos θ dω`,
    /// per channel.
    pub fn upper_irradiance(&self) -> [f64; 3] {
        let (w, h) = self.radiance.size();
        let mut e = [0.0f64; 3];
        for y in 0..h {
            let omega = self.texel_solid_angle(y) as f64;
            for x in 0..w {
                let cos = self.direction_of(x as f32, y as f32).y as f64;
                if cos > 0.0 {
                    let l = self.radiance.get(x, y);
                    for c in 0..3 {
                        e[c] += l[c] as f64 * omega * cos;
                    }
                }
            }
        }
        e
    }

    /// Radiance of an unshadowed Lambertian ground of `albedo` lit by the map's upper
    /// hemisphere: `ρ/π · ∫_{upper} L cos θ dω`.
    pub fn lambertian_ground(&self, albedo: Rgb) -> Rgb {
        let e = self.upper_irradiance();
        [0, 1, 2].map(|c| albedo[c] * (e[c] / std::f64::consts::PI) as f32)
    }

    /// Reduces the map to at most `n` distant lights by median cut; the lights' total
    /// irradiance equals [`EnvMap::total_light`] (up to float rounding).
    pub fn median_cut(&self, n: usize) -> Vec<DirLight> {
        MedianCut::new(self).lights(n.max(1))
    }
}

/// Summed-area tables of the quantities median cut needs per region.
struct MedianCut<'a> {
    env: &'a EnvMap,
    w: usize,
    /// Per texel: energy (luminance × solid angle), RGB light, energy-weighted direction.
    tables: [Vec<f64>; 7],
}

#[derive(Debug, Clone, Copy)]
struct Region {
    x0: usize,
    y0: usize,
    x1: usize,
    y1: usize,
    energy: f64,
}

impl PartialEq for Region {
    fn eq(&self, other: &Self) -> bool {
        self.energy == other.energy
    }
}
impl Eq for Region {}
impl PartialOrd for Region {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Region {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.energy.total_cmp(&other.energy)
    }
}

impl<'a> MedianCut<'a> {
    fn new(env: &'a EnvMap) -> Self {
        let (w, h) = env.radiance.size();
        let stride = w + 1;
        let mut tables: [Vec<f64>; 7] = std::array::from_fn(|_| vec![0.0; stride * (h + 1)]);
        for y in 0..h {
            let omega = env.texel_solid_angle(y) as f64;
            for x in 0..w {
                let p = env.radiance.get(x, y);
                let e = luminance(p) as f64 * omega;
                let d = env.direction_of(x as f32, y as f32);
                let values = [
                    e,
                    p[0] as f64 * omega,
                    p[1] as f64 * omega,
                    p[2] as f64 * omega,
                    e * d.x as f64,
                    e * d.y as f64,
                    e * d.z as f64,
                ];
                let i = (y + 1) * stride + x + 1;
                for (t, v) in tables.iter_mut().zip(values) {
                    t[i] = v + t[i - 1] + t[i - stride] - t[i - stride - 1];
                }
            }
        }
        Self { env, w, tables }
    }

    fn sum(&self, table: usize, x0: usize, y0: usize, x1: usize, y1: usize) -> f64 {
        let s = self.w + 1;
        let t = &self.tables[table];
        t[y1 * s + x1] - t[y0 * s + x1] - t[y1 * s + x0] + t[y0 * s + x0]
    }

    fn region(&self, x0: usize, y0: usize, x1: usize, y1: usize) -> Region {
        Region {
            x0,
            y0,
            x1,
            y1,
            energy: self.sum(0, x0, y0, x1, y1),
        }
    }

    /// Splits a region in two halves of equal energy across its longer angular side.
    fn split(&self, r: Region) -> Option<(Region, Region)> {
        let (w, h) = self.env.radiance.size();
        let rows_mid = (r.y0 + r.y1) as f32 / 2.0 * PI / h as f32;
        let width_angle = (r.x1 - r.x0) as f32 * 2.0 * PI / w as f32 * rows_mid.sin();
        let height_angle = (r.y1 - r.y0) as f32 * PI / h as f32;
        let along_x = (width_angle >= height_angle && r.x1 - r.x0 > 1) || r.y1 - r.y0 <= 1;
        let (lo, hi) = if along_x { (r.x0, r.x1) } else { (r.y0, r.y1) };
        if hi - lo < 2 {
            return None;
        }
        let energy_below = |k: usize| {
            if along_x {
                self.sum(0, r.x0, r.y0, k, r.y1)
            } else {
                self.sum(0, r.x0, r.y0, r.x1, k)
            }
        };
        // Smallest k in (lo, hi) with at least half the energy below it.
        let (mut a, mut b) = (lo + 1, hi - 1);
        while a < b {
            let m = (a + b) / 2;
            if energy_below(m) * 2.0 >= r.energy {
                b = m;
            } else {
                a = m + 1;
            }
        }
        let k = a;
        Some(if along_x {
            (
                self.region(r.x0, r.y0, k, r.y1),
                self.region(k, r.y0, r.x1, r.y1),
            )
        } else {
            (
                self.region(r.x0, r.y0, r.x1, k),
                self.region(r.x0, k, r.x1, r.y1),
            )
        })
    }

    fn lights(&self, n: usize) -> Vec<DirLight> {
        let (w, h) = self.env.radiance.size();
        let mut done = Vec::new();
        let mut heap = BinaryHeap::from([self.region(0, 0, w, h)]);
        while done.len() + heap.len() < n {
            let Some(r) = heap.pop() else { break };
            match self.split(r) {
                Some((a, b)) => {
                    heap.push(a);
                    heap.push(b);
                }
                None => done.push(r),
            }
        }
        done.extend(heap);
        done.into_iter()
            .filter_map(|r| {
                let rgb = [1, 2, 3].map(|t| self.sum(t, r.x0, r.y0, r.x1, r.y1) as f32);
                if rgb.iter().all(|&c| c <= 0.0) {
                    return None;
                }
                let d = Vec3::new(
                    self.sum(4, r.x0, r.y0, r.x1, r.y1) as f32,
                    self.sum(5, r.x0, r.y0, r.x1, r.y1) as f32,
                    self.sum(6, r.x0, r.y0, r.x1, r.y1) as f32,
                );
                // A coloured region with zero luminance has no energy centroid: use its centre.
                let direction = if d.length() > 1e-12 {
                    d.normalize()
                } else {
                    self.env.direction_of(
                        (r.x0 + r.x1) as f32 / 2.0 - 0.5,
                        (r.y0 + r.y1) as f32 / 2.0 - 0.5,
                    )
                };
                Some(DirLight {
                    direction,
                    irradiance: rgb,
                })
            })
            .collect()
    }
}

/// Where a render's lighting comes from, as a user names it: `sky`, `uniform`, `none`,
/// or the path of a latitude–longitude `.hdr` / `.exr` file (a file literally named like
/// one of the words is given as `./sky`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum EnvSource {
    /// An HDR environment file.
    File(PathBuf),
    /// The built-in sky ([`EnvMap::sky`]).
    Sky,
    /// A uniform white environment of radiance 1 (a furnace).
    Uniform,
    /// No relighting: a field of photographs shown as captured.
    None,
}

/// Resolution of the built-in uniform environment (texels per row); it is constant, so
/// any size projects the same.
const UNIFORM_SIZE: usize = 64;

impl EnvSource {
    /// The environment, where `need` (what it is for) requires one: `none` is refused
    /// as a `--env`.
    pub fn load_required(&self, need: &str) -> Result<EnvMap> {
        let allowed = format!("an environment ({need})");
        self.load()?
            .ok_or_else(|| crate::BadArgument::new("--env", "none", allowed).into())
    }

    /// The environment: `None` for [`EnvSource::None`].
    pub fn load(&self) -> Result<Option<EnvMap>> {
        Ok(match self {
            EnvSource::File(path) => Some(EnvMap::load(path)?),
            EnvSource::Sky => Some(EnvMap::sky()),
            EnvSource::Uniform => Some(EnvMap::uniform([1.0; 3], UNIFORM_SIZE)),
            EnvSource::None => None,
        })
    }

    /// A short name for reports: the file's stem, or the word.
    pub fn name(&self) -> String {
        match self {
            EnvSource::File(p) => p
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| p.display().to_string()),
            other => other.to_string(),
        }
    }
}

impl FromStr for EnvSource {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Self, String> {
        Ok(match s {
            "" => {
                return Err(
                    "empty environment: expected a .hdr/.exr file, sky, uniform or none".into(),
                );
            }
            "sky" => EnvSource::Sky,
            "uniform" => EnvSource::Uniform,
            "none" => EnvSource::None,
            path => EnvSource::File(PathBuf::from(path)),
        })
    }
}

impl fmt::Display for EnvSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EnvSource::File(p) => write!(f, "{}", p.display()),
            EnvSource::Sky => f.write_str("sky"),
            EnvSource::Uniform => f.write_str("uniform"),
            EnvSource::None => f.write_str("none"),
        }
    }
}

impl serde::Serialize for EnvSource {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> serde::Deserialize<'de> for EnvSource {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mapping_matches_the_ict_convention() {
        let env = EnvMap::uniform([1.0; 3], 64);
        // Image centre looks toward -z; top row is the zenith.
        let centre = env.direction_of(63.5, 31.5);
        assert!((centre - Vec3::NEG_Z).length() < 1e-3, "{centre}");
        assert!(env.direction_of(10.0, -0.5).y > 0.999);
        for d in [Vec3::new(0.3, 0.5, -0.8), Vec3::new(-0.9, -0.1, 0.2)] {
            let d = d.normalize();
            let t = env.texel_of(d);
            assert!((env.direction_of(t.x, t.y) - d).length() < 1e-4);
        }
        let yawed = env.rotated(0.7);
        let d = Vec3::new(0.2, 0.1, 0.9).normalize();
        let t = yawed.texel_of(d);
        assert!((yawed.direction_of(t.x, t.y) - d).length() < 1e-4);
    }

    #[test]
    fn solid_angles_sum_to_the_sphere() {
        let env = EnvMap::uniform([2.0; 3], 32);
        let total = env.total_light();
        assert!((total[0] - 8.0 * PI).abs() < 1e-3, "{total:?}");
    }

    #[test]
    fn median_cut_keeps_total_light_and_isolates_the_sun() {
        let mut img = Image::new(128, 64, [0.05f32, 0.07, 0.1]);
        img.set(40, 20, [5000.0, 4000.0, 3000.0]);
        let env = EnvMap::from_image(img).unwrap();
        let lights = env.median_cut(64);
        assert!(lights.len() <= 64 && lights.len() > 32);
        let total = env.total_light();
        let sum = lights.iter().fold([0.0f32; 3], |acc, l| {
            [0, 1, 2].map(|c| acc[c] + l.irradiance[c])
        });
        for c in 0..3 {
            assert!(
                (sum[c] - total[c]).abs() <= 1e-4 * total[c],
                "{sum:?} vs {total:?}"
            );
        }
        let sun_dir = env.direction_of(40.0, 20.0);
        let sun_light = env.texel_solid_angle(20) * 5000.0;
        let brightest = lights
            .iter()
            .max_by(|a, b| a.irradiance[0].total_cmp(&b.irradiance[0]))
            .unwrap();
        assert!((brightest.direction - sun_dir).length() < 1e-3);
        // The sun's light is in one light, with at most a little sky mixed in.
        assert!((brightest.irradiance[0] - sun_light).abs() < 0.01 * sun_light);
    }

    #[test]
    fn built_in_sky_is_sun_dominated() {
        let env = EnvMap::sky();
        let sun =
            crate::light::direction_from_azimuth_elevation(60f32.to_radians(), 40f32.to_radians());
        let (mut near_sun, mut total) = (0.0, 0.0);
        for y in 0..env.image().height() {
            let omega = env.texel_solid_angle(y);
            for x in 0..env.image().width() {
                let e = luminance(env.image().get(x, y)) * omega;
                total += e;
                if env.direction_of(x as f32, y as f32).dot(sun) > 3f32.to_radians().cos() {
                    near_sun += e;
                }
            }
        }
        let share = near_sun / total;
        assert!(share > 0.5 && share < 0.9, "sun share {share}");
        // Median cut puts the sun's light into lights pointing at it.
        let lights = env.median_cut(64);
        let toward_sun: f32 = lights
            .iter()
            .filter(|l| l.direction.dot(sun) > 3f32.to_radians().cos())
            .map(|l| luminance(l.irradiance))
            .sum();
        assert!((toward_sun / total - share).abs() < 0.05);
    }

    #[test]
    fn bad_texels_follow_the_stated_rule() {
        let mut img = Image::new(8, 4, [1.0f32; 3]);
        img.set(3, 2, [f32::NAN, 0.0, 0.0]);
        let err = EnvMap::from_image(img).unwrap_err().to_string();
        assert!(err.contains("(3, 2)"), "{err}");
        let mut img = Image::new(8, 4, [1.0f32; 3]);
        img.set(1, 1, [-1.0, 0.5, 0.0]);
        let env = EnvMap::from_image(img).unwrap();
        assert_eq!(env.clamped_texels(), 1);
        assert_eq!(env.image().get(1, 1), [0.0, 0.5, 0.0]);
    }

    #[test]
    fn environment_sources_parse_once_and_round_trip() {
        for (text, source) in [
            ("sky", EnvSource::Sky),
            ("uniform", EnvSource::Uniform),
            ("none", EnvSource::None),
            ("./sky", EnvSource::File(PathBuf::from("./sky"))),
            (
                "maps/grace.hdr",
                EnvSource::File(PathBuf::from("maps/grace.hdr")),
            ),
        ] {
            assert_eq!(text.parse::<EnvSource>().unwrap(), source);
            assert_eq!(source.to_string(), text);
        }
        let e = "".parse::<EnvSource>().unwrap_err().to_string();
        assert!(e.contains("empty environment") && e.contains("sky"), "{e}");
        assert_eq!(EnvSource::File("a/grace.hdr".into()).name(), "grace");
        assert!(EnvSource::None.load().unwrap().is_none());
        let furnace = EnvSource::Uniform.load().unwrap().unwrap();
        let total = furnace.total_light();
        assert!((total[0] - 4.0 * PI).abs() < 1e-3, "{total:?}");
        let missing = EnvSource::File("no/such.hdr".into()).load().unwrap_err();
        assert!(missing.to_string().contains("no/such.hdr"), "{missing}");
    }

    #[test]
    fn a_mix_of_one_map_is_the_map_and_weights_add_light() {
        let sky = EnvMap::sky().rotated(0.4);
        let one = EnvMap::mix(&[(&sky, 1.0)]).unwrap();
        for d in [Vec3::Y, Vec3::new(0.3, 0.2, -0.9).normalize(), Vec3::NEG_Y] {
            let (a, b) = (sky.radiance(d), one.radiance(d));
            for c in 0..3 {
                assert!(
                    (a[c] - b[c]).abs() <= 1e-3 * a[c].abs().max(1.0),
                    "{a:?} vs {b:?}"
                );
            }
        }
        let white = EnvMap::uniform([2.0; 3], 8);
        let half = EnvMap::mix(&[(&white, 0.25), (&white.scaled(3.0), 0.5)]).unwrap();
        // 0.25 x 2 + 0.5 x 6 = 3.5 everywhere.
        assert!(
            half.image()
                .pixels()
                .iter()
                .all(|p| (p[0] - 3.5).abs() < 1e-5)
        );
        let e = EnvMap::mix(&[]).unwrap_err().to_string();
        assert!(
            e.contains("environment mix") && e.contains("no environment"),
            "{e}"
        );
    }
}
