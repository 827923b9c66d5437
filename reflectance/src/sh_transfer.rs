//! A view's transfer to an L2 light (docs/export.md): relighting is linear in the
//! basis images, `I = Σ_k B_k a_k`, and the coefficient `a_k` of condition `k` is the
//! light over the condition's region divided by the light the condition delivers
//! ([`crate::project`]). For a light `L = Σ_i c_i Y_i` ([`frf_core::sh`]) that is
//! `a_k = Σ_i c_i W_ki` with `W_ki = ∫_{Ω_k} Y_i dω / Σ_{l∈k} E_l`, so
//! `I = Σ_i c_i T_i` with the texel's transfer `T_i = Σ_k B_k W_ki`: nine RGB images
//! per view, exact (no fitting), which an engine multiplies by its light probe's
//! coefficients.
//!
//! `W` is the projection of each basis function, as a signed map of
//! [`SH_MAP_HEIGHT`] rows, by the same [`Projector`] that relights an environment, with
//! the floor conditions lit by the light's own lower hemisphere
//! ([`FloorModel::Environment`]): for the map frf makes of an L2 light
//! ([`ShLight::to_env`]) the transfer and the relighting agree to float rounding.

use frf_core::env::{EnvMap, SH_MAP_HEIGHT};
use frf_core::image::{Image, Rgb};
use frf_core::sh::{SH_COUNT, ShLight, sh_basis};

use crate::error::Result;
use crate::project::{FloorModel, Projector};

/// Per condition: the weight of each SH coefficient in its relighting coefficient, per
/// channel (`W_ki`, see the module text), for a view at one turntable angle.
pub type ShWeights = Vec<[Rgb; SH_COUNT]>;

/// `W` for views at each of `turntables` (radians).
pub fn sh_weights(projector: &Projector, turntables: &[f32]) -> Result<Vec<ShWeights>> {
    let mut out = vec![vec![[[0.0f32; 3]; SH_COUNT]; projector.conditions()]; turntables.len()];
    let probe = EnvMap::uniform([0.0; 3], SH_MAP_HEIGHT);
    for i in 0..SH_COUNT {
        let map = EnvMap::signed(Image::from_fn(2 * SH_MAP_HEIGHT, SH_MAP_HEIGHT, |x, y| {
            [sh_basis(probe.direction_of(x as f32, y as f32))[i]; 3]
        }))?;
        let lights = projector.region_light_many(&map, turntables, FloorModel::Environment);
        for (view, light) in out.iter_mut().zip(lights) {
            for (k, a) in projector.coefficients_of(&light).into_iter().enumerate() {
                view[k][i] = a;
            }
        }
    }
    Ok(out)
}

/// The relighting coefficients of `light` from `W`: `a_k = Σ_i c_i W_ki`.
pub fn coefficients_of(weights: &ShWeights, light: &ShLight) -> Vec<Rgb> {
    weights
        .iter()
        .map(|w| {
            let mut a = [0.0f32; 3];
            for (wi, ci) in w.iter().zip(&light.coefficients) {
                for c in 0..3 {
                    a[c] += wi[c] * ci[c];
                }
            }
            a
        })
        .collect()
}

/// A texel's transfer `T_i = Σ_k B_k W_ki` from its basis values `basis[k]`.
pub fn texel_transfer(weights: &ShWeights, basis: impl Iterator<Item = Rgb>) -> [Rgb; SH_COUNT] {
    let mut t = [[0.0f32; 3]; SH_COUNT];
    for (b, w) in basis.zip(weights) {
        for (ti, wi) in t.iter_mut().zip(w) {
            for c in 0..3 {
                ti[c] += b[c] * wi[c];
            }
        }
    }
    t
}
