//! Light as real spherical harmonics up to band 2 ("L2": 9 coefficients per colour
//! channel), the form of the light probes of three.js, Unity, Unreal and Godot.
//!
//! **The convention** (declared in every file frf writes, [`Convention`]): the radiance
//! arriving from unit direction `d = (x, y, z)` is `L(d) = Σ_i c_i Y_i(d)`, with `d` in
//! frf's subject frame, which is glTF's and three.js's world frame (`+y` up,
//! right-handed; an environment map's centre looks toward `-z`, [`crate::env`]). The
//! basis is the orthonormal real one (`∫ Y_i Y_j dω = δ_ij`) in three.js's
//! `SphericalHarmonics3` order and signs, without the Condon–Shortley phase:
//!
//! | i | (l, m) | `Y_i(x, y, z)` |
//! |---|---|---|
//! | 0 | (0, 0) | 0.282095 |
//! | 1 | (1, −1) | 0.488603 y |
//! | 2 | (1, 0) | 0.488603 z |
//! | 3 | (1, 1) | 0.488603 x |
//! | 4 | (2, −2) | 1.092548 xy |
//! | 5 | (2, −1) | 1.092548 yz |
//! | 6 | (2, 0) | 0.315392 (3z² − 1) |
//! | 7 | (2, 1) | 1.092548 xz |
//! | 8 | (2, 2) | 0.546274 (x² − y²) |
//!
//! The coefficients are of radiance (what three.js's `LightProbe.sh` holds and its
//! `getAt` evaluates), not of irradiance; [`ShLight::irradiance`] is the cosine-convolved
//! light a matte surface receives (Ramamoorthi and Hanrahan's factors π, 2π/3, π/4 per
//! band). The Condon–Shortley form negates the four coefficients of odd `m`
//! ([`ShLight::condon_shortley`]); Unity's shader form is seven vectors
//! ([`ShLight::unity_shader_vectors`]). docs/export.md says how engines map onto it.
//!
//! An L2 light is smooth: a sun in it is a broad lobe, and its reconstruction rings
//! negative opposite a bright source (`EnvMap::from_sh` keeps those lobes,
//! `EnvMap::from_sh_clamped` counts them). The maps are made in `crate::env`.

use std::f32::consts::PI;
use std::path::Path;

use glam::{Mat3, Vec3};
use serde::{Deserialize, Serialize};

use crate::error::{CoreError, Result};
use crate::image::Rgb;
use crate::light::{MAX_SUN_DIAMETER_DEG, MAX_TOTAL_LIGHT, SunFault, sun_fault};

/// Coefficients per channel of an L2 light.
pub const SH_COUNT: usize = 9;

/// `(l, m)` of each coefficient, in order.
pub const SH_ORDER: [(i32, i32); SH_COUNT] = [
    (0, 0),
    (1, -1),
    (1, 0),
    (1, 1),
    (2, -2),
    (2, -1),
    (2, 0),
    (2, 1),
    (2, 2),
];

/// The format name of frf's SH light files.
pub const SH_FORMAT: &str = "frf-sh-l2";
/// Their version.
pub const SH_VERSION: u32 = 1;

/// The basis' normalising constants (see the module text): band 0's, band 1's, then
/// band 2's for `xy`, `yz` and `xz`, for `3z² − 1` and for `x² − y²`.
const K0: f32 = 0.282_095;
const K1: f32 = 0.488_603;
const K2: f32 = 1.092_548;
const K6: f32 = 0.315_392;
const K8: f32 = 0.546_274;

/// The basis functions at unit direction `d` (see the module text).
pub fn sh_basis(d: Vec3) -> [f32; SH_COUNT] {
    let (x, y, z) = (d.x, d.y, d.z);
    [
        K0,
        K1 * y,
        K1 * z,
        K1 * x,
        K2 * x * y,
        K2 * y * z,
        K6 * (3.0 * z * z - 1.0),
        K2 * x * z,
        K8 * (x * x - y * y),
    ]
}

/// The cosine lobe's factor per band (`Â_l`): the irradiance's coefficient is `Â_l c_i`.
pub const COSINE_LOBE: [f32; 3] = [PI, 2.0 * PI / 3.0, PI / 4.0];

/// How the engines' glTF importers place frf's (glTF's) directions in their own world
/// frames, as [`ShLight::in_frame`] takes them: `(engine, to)`, `d_engine = to · d`.
/// three.js, Godot and Bevy keep glTF's axes (`+y` up, right-handed); Unity's importers
/// (UnityGLTF, glTFast) negate `x` to make the frame left-handed. Unreal's (z up,
/// left-handed, centimetres) is not listed: its importer's axis order could not be
/// checked here (docs/export.md).
pub const ENGINE_FRAMES: [(&str, Mat3); 4] = [
    ("three.js", Mat3::IDENTITY),
    ("Godot", Mat3::IDENTITY),
    ("Bevy", Mat3::IDENTITY),
    ("Unity", Mat3::from_cols(Vec3::NEG_X, Vec3::Y, Vec3::Z)),
];

/// The convention a file declares (see the module text); a file declaring another is
/// refused rather than misread.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Convention {
    /// `"l,m"` of each coefficient, in order.
    pub order: Vec<String>,
    /// How the basis is normalised.
    pub normalisation: String,
    /// Whether the Condon–Shortley phase `(−1)^m` is in the basis.
    pub condon_shortley_phase: bool,
    /// What the coefficients are of.
    pub quantity: String,
    /// The frame of the directions.
    pub frame: String,
}

impl Convention {
    /// Each field in which it differs from `other`, in words (`condon_shortley_phase`:
    /// true here, false there).
    /// Compared as written (its JSON), so a field added to it is compared too.
    pub fn differences(&self, other: &Self) -> Vec<String> {
        let json = |c: &Self| match serde_json::to_value(c) {
            Ok(serde_json::Value::Object(m)) => m,
            _ => serde_json::Map::new(),
        };
        let (mine, theirs) = (json(self), json(other));
        (mine.iter())
            .filter(|(k, v)| theirs.get(*k) != Some(*v))
            .map(|(k, v)| {
                let frf = theirs.get(k).map_or("none".into(), ToString::to_string);
                format!("{k} {v}, frf's {frf}")
            })
            .collect()
    }

    /// frf's convention.
    pub fn frf() -> Self {
        Self {
            order: SH_ORDER.iter().map(|(l, m)| format!("{l},{m}")).collect(),
            normalisation: "orthonormal real (three.js SphericalHarmonics3)".into(),
            condon_shortley_phase: false,
            quantity: "radiance".into(),
            frame: "+y up, right-handed, the map's centre toward -z (glTF, three.js)".into(),
        }
    }
}

/// An L2 light: radiance coefficients per channel (see the module text).
#[derive(Debug, Clone, PartialEq)]
pub struct ShLight {
    /// `c_i`, RGB.
    pub coefficients: [Rgb; SH_COUNT],
}

/// The file form of an [`ShLight`].
#[derive(Debug, Clone, Serialize, Deserialize)]
struct ShFile {
    format: String,
    version: u32,
    convention: Convention,
    coefficients: Vec<[f32; 3]>,
    #[serde(default, skip_serializing_if = "String::is_empty")]
    source: String,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    suns: Vec<ShSun>,
}

/// A sun a light file carries beside its L2 coefficients (`frf env-sh --suns`: the suns
/// found in a map, the coefficients those of the map less them): a distant disc that
/// frf paints into the light's map ([`crate::env::EnvMap::load`]) and a player relights
/// sharply, as frf relights a map's suns.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ShSun {
    /// Toward the sun, unit, the light's frame.
    pub direction: [f32; 3],
    /// Angular diameter, degrees (above 0, at most [`MAX_SUN_DIAMETER_DEG`]).
    pub diameter_deg: f32,
    /// `∫ L dω` over the disc, per channel.
    pub illuminance: Rgb,
}

impl ShLight {
    /// Radiance from unit direction `d`.
    pub fn radiance(&self, d: Vec3) -> Rgb {
        weighted(&self.coefficients, sh_basis(d))
    }

    /// Irradiance on a surface of unit normal `n`, `∫ L max(n · ω, 0) dω`, of the light
    /// as L2 represents it.
    pub fn irradiance(&self, n: Vec3) -> Rgb {
        let mut basis = sh_basis(n);
        for (b, (l, _)) in basis.iter_mut().zip(SH_ORDER) {
            *b *= COSINE_LOBE[l as usize];
        }
        weighted(&self.coefficients, basis)
    }

    /// The coefficients with the Condon–Shortley phase: those of odd `m` negated (the
    /// ordering of many papers and tools). Its own inverse.
    pub fn condon_shortley(&self) -> [Rgb; SH_COUNT] {
        let mut c = self.coefficients;
        for (i, (_, m)) in SH_ORDER.iter().enumerate() {
            if m % 2 != 0 {
                c[i] = c[i].map(|v| -v);
            }
        }
        c
    }

    /// From coefficients with the Condon–Shortley phase ([`ShLight::condon_shortley`]).
    pub fn from_condon_shortley(c: [Rgb; SH_COUNT]) -> Self {
        Self::from_coefficients(Self::from_coefficients(c).condon_shortley())
    }

    /// Wraps coefficients in frf's convention.
    pub fn from_coefficients(coefficients: [Rgb; SH_COUNT]) -> Self {
        Self { coefficients }
    }

    /// The same light in a frame whose directions are `to · d` (`to` orthogonal: a
    /// rotation, or a reflection such as an engine's change of handedness): the
    /// coefficients whose radiance at `to · d` is this light's at `d`, exactly (an L2
    /// light is a polynomial of degree 2 on the sphere, `a + b · d + dᵀ Q d`, which `to`
    /// maps to `a + (to b) · d' + d'ᵀ (to Q toᵀ) d'`). [`ENGINE_FRAMES`] names the
    /// engines' frames.
    pub fn in_frame(&self, to: Mat3) -> Self {
        let channel = |ch: usize| -> [f32; SH_COUNT] {
            let c = |i: usize| self.coefficients[i][ch];
            let b = to * Vec3::new(c(3), c(1), c(2)) * K1;
            // The quadratic part, traceless (on the sphere 3z² − 1 = 2z² − x² − y²).
            let (xy, yz, xz) = (K2 * c(4) / 2.0, K2 * c(5) / 2.0, K2 * c(7) / 2.0);
            let (xx, yy, zz) = (
                -K6 * c(6) + K8 * c(8),
                -K6 * c(6) - K8 * c(8),
                2.0 * K6 * c(6),
            );
            let q = Mat3::from_cols(
                Vec3::new(xx, xy, xz),
                Vec3::new(xy, yy, yz),
                Vec3::new(xz, yz, zz),
            );
            let q = to * q * to.transpose();
            [
                c(0),
                b.y / K1,
                b.z / K1,
                b.x / K1,
                2.0 * q.y_axis.x / K2,
                2.0 * q.z_axis.y / K2,
                q.z_axis.z / (2.0 * K6),
                2.0 * q.z_axis.x / K2,
                (q.x_axis.x - q.y_axis.y) / (2.0 * K8),
            ]
        };
        let per = [channel(0), channel(1), channel(2)];
        let out = std::array::from_fn(|i| [per[0][i], per[1][i], per[2][i]]);
        Self::from_coefficients(out)
    }

    /// Unity's seven shader vectors (`unity_SHAr, SHAg, SHAb, SHBr, SHBg, SHBb, SHC`),
    /// whose `ShadeSH9(n)` — `SHA·(n, 1) + SHB·(xy, yz, z², zx) + SHC·(x² − y²)` per
    /// channel — is [`ShLight::irradiance`] over π (what a matte albedo multiplies), for
    /// `n` in this frame. SHC's fourth component is 1.
    pub fn unity_shader_vectors(&self) -> [[f32; 4]; 7] {
        let c = &self.coefficients;
        let (a0, a1, a2) = (
            COSINE_LOBE[0] / PI,
            COSINE_LOBE[1] / PI,
            COSINE_LOBE[2] / PI,
        );
        let mut out = [[0.0f32; 4]; 7];
        for ch in 0..3 {
            out[ch] = [
                a1 * K1 * c[3][ch],
                a1 * K1 * c[1][ch],
                a1 * K1 * c[2][ch],
                a0 * K0 * c[0][ch] - a2 * K6 * c[6][ch],
            ];
            out[3 + ch] = [
                a2 * K2 * c[4][ch],
                a2 * K2 * c[5][ch],
                a2 * 3.0 * K6 * c[6][ch],
                a2 * K2 * c[7][ch],
            ];
            out[6][ch] = a2 * K8 * c[8][ch];
        }
        out[6][3] = 1.0;
        out
    }

    /// Writes the light as JSON (temporary file, then renamed), naming `source`.
    pub fn save(&self, path: &Path, source: &str) -> Result<()> {
        self.save_with_suns(path, source, &[])
    }

    /// [`ShLight::save`] with `suns` beside the coefficients.
    pub fn save_with_suns(&self, path: &Path, source: &str, suns: &[ShSun]) -> Result<()> {
        let file = ShFile {
            format: SH_FORMAT.into(),
            version: SH_VERSION,
            convention: Convention::frf(),
            coefficients: self.coefficients.to_vec(),
            source: source.into(),
            suns: suns.to_vec(),
        };
        let text = serde_json::to_string_pretty(&file)
            .map_err(|e| CoreError::bad_file(path, e.to_string()))?;
        crate::atomic::write_bytes_atomic(path, text.as_bytes())
    }

    /// Reads a light written by [`ShLight::save`] (or by hand in its form), refusing
    /// another format, version or convention, a count other than 9, non-finite values
    /// and a total light beyond [`MAX_TOTAL_LIGHT`].
    pub fn load(path: &Path) -> Result<Self> {
        Ok(Self::load_with_suns(path)?.0)
    }

    /// [`ShLight::load`] and the suns the file carries, each checked: a direction (finite,
    /// not zero), a diameter above 0 and at most [`MAX_SUN_DIAMETER_DEG`], an illuminance
    /// finite, not negative and at most [`MAX_TOTAL_LIGHT`].
    pub fn load_with_suns(path: &Path) -> Result<(Self, Vec<ShSun>)> {
        let bytes = std::fs::read(path).map_err(|e| CoreError::io(path, e))?;
        // A byte-order mark some editors write is not JSON: read past it.
        let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(&bytes);
        let file: ShFile = serde_json::from_slice(bytes).map_err(|e| {
            CoreError::bad_file(path, format!("not an SH light ({SH_FORMAT} JSON): {e}"))
        })?;
        let bad = |m: String| Err(CoreError::bad_file(path, m));
        if file.format != SH_FORMAT {
            return bad(format!("format {:?}, expected {SH_FORMAT:?}", file.format));
        }
        if file.version != SH_VERSION {
            return bad(format!(
                "version {} of {SH_FORMAT}; this frf reads version {SH_VERSION}",
                file.version
            ));
        }
        let differ = file.convention.differences(&Convention::frf());
        if !differ.is_empty() {
            return bad(format!(
                "its convention is not frf's: {} (convert it first: docs/export.md)",
                differ.join("; ")
            ));
        }
        let coefficients: [Rgb; SH_COUNT] = match file.coefficients.try_into() {
            Ok(c) => c,
            Err(c) => {
                let c: Vec<[f32; 3]> = c;
                return bad(format!("{} coefficients, expected {SH_COUNT}", c.len()));
            }
        };
        if let Some(i) = coefficients
            .iter()
            .position(|c| c.iter().any(|v| !v.is_finite()))
        {
            return bad(format!("coefficient {i} is not finite"));
        }
        // Band 0 is the light's total (√(4π) c_0): below zero it would take light away.
        if let Some(c) = coefficients[0].iter().position(|&v| v < 0.0) {
            return bad(format!(
                "band 0 (its total light) is negative in channel {c} ({:e}): a light \
                 cannot take light away",
                coefficients[0][c]
            ));
        }
        // ∫ L dω = √(4π) c_0: the band-0 term carries all of the total light.
        let total = coefficients[0].map(|c| (c as f64 * (4.0 * std::f64::consts::PI).sqrt()).abs());
        if total.iter().any(|&t| t > MAX_TOTAL_LIGHT) {
            return bad(format!(
                "its total light {:.1e} is beyond what relighting can sum (at most {MAX_TOTAL_LIGHT:.0e})",
                total.iter().fold(0.0f64, |a, &b| a.max(b))
            ));
        }
        for (k, sun) in file.suns.iter().enumerate() {
            let (d, e) = (sun.direction, sun.illuminance);
            let problem = match sun_fault(Vec3::from(d), sun.diameter_deg, e) {
                None => continue,
                Some(SunFault::Direction) => format!("direction {d:?} is not a direction"),
                Some(SunFault::Diameter) => format!(
                    "diameter {}° is not within (0, {MAX_SUN_DIAMETER_DEG}]°",
                    sun.diameter_deg
                ),
                Some(SunFault::Illuminance) => {
                    format!("illuminance {e:?} is not a finite, non-negative light")
                }
            };
            return bad(format!("sun {k}'s {problem}"));
        }
        Ok((Self { coefficients }, file.suns))
    }
}

/// `Σ_i c_i w_i` per channel: coefficients weighted by the basis (or any nine weights:
/// the cosine-convolved basis, another convention's).
pub fn weighted(c: &[Rgb; SH_COUNT], w: [f32; SH_COUNT]) -> Rgb {
    let mut out = [0.0f32; 3];
    for (ci, wi) in c.iter().zip(w) {
        for ch in 0..3 {
            out[ch] += ci[ch] * wi;
        }
    }
    out
}
