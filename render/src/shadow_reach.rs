//! How far a subject's shadow reaches over the ground, and the patch of shadow maps that
//! holds it. The maps cover a square patch under the subject fixed at ingest
//! (`--shadow-extent`, 3 m in the original) and fade to unshadowed toward its edge
//! ([`crate::shadow::edge_fade`]); a low light's shadow is longer than that. What counts
//! is the light that makes the shadow: the lights of an environment, highest first, that
//! together deliver [`GROUND_LIGHT_SHARE`] of the irradiance of the unshadowed ground;
//! the lowest of them sets the reach, `radius + height / tan(elevation)` for a subject of
//! `height` standing within `radius` of its axis. Lower lights carry the rest, and their
//! longer shadows are faint.
//!
//! `frf render` warns when a scene's shadow reaches past the fade of its field's patch,
//! and `frf ingest --for SCENE` makes the patch large enough for the scene's lighting.

use frf_core::env::EnvMap;
use frf_core::image::luminance;

use crate::shadow::EDGE_FADE_FROM;

/// The share of the ground's irradiance whose shadows must fit the patch.
pub const GROUND_LIGHT_SHARE: f32 = 0.9;
/// Lights of an environment considered (median cut).
const LIGHTS: usize = 256;
/// Lights lower than this (radians, 3°) would cast a shadow of unbounded length: they
/// count as this high.
const LOWEST_ELEVATION: f32 = 0.052;
/// A standing person's height and the radius around its axis it stays within, metres:
/// what is assumed when no hull is known (before ingest carves one).
pub const NOMINAL_SUBJECT: (f32, f32) = (1.9, 0.4);

/// The elevation (radians) of the lowest of the lights of `env` that, highest first,
/// deliver [`GROUND_LIGHT_SHARE`] of the unshadowed ground's irradiance; `None` when no
/// light comes from above.
pub fn shadow_light_elevation(env: &EnvMap) -> Option<f32> {
    let mut lights: Vec<(f32, f32)> = env
        .median_cut(LIGHTS)
        .iter()
        .filter(|l| l.direction.y > 0.0)
        .map(|l| {
            let d = l.direction.normalize();
            (d.y.asin(), luminance(l.irradiance) * d.y)
        })
        .filter(|(_, e)| *e > 0.0)
        .collect();
    let total: f32 = lights.iter().map(|l| l.1).sum();
    if total <= 0.0 {
        return None;
    }
    lights.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut sum = 0.0;
    for (elevation, e) in lights {
        sum += e;
        if sum >= GROUND_LIGHT_SHARE * total {
            return Some(elevation.max(LOWEST_ELEVATION));
        }
    }
    None
}

/// The lowest [`shadow_light_elevation`] of `envs` (a scene's lighting keys): `None`
/// when none lights the ground from above.
pub fn lowest_shadow_light_elevation<'a>(
    envs: impl IntoIterator<Item = &'a EnvMap>,
) -> Option<f32> {
    envs.into_iter()
        .filter_map(shadow_light_elevation)
        .reduce(f32::min)
}

/// How far from the subject's axis its shadow reaches (metres) under a light at
/// `elevation` (radians), for a subject of `(height, radius)`.
pub fn shadow_reach(elevation: f32, (height, radius): (f32, f32)) -> f32 {
    radius + height / elevation.max(LOWEST_ELEVATION).tan()
}

/// The side (metres) of a patch whose maps hold a shadow reaching `reach` metres before
/// their fade begins.
pub fn patch_side_holding(reach: f32) -> f32 {
    2.0 * reach / EDGE_FADE_FROM
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sun_sets_the_reach_and_a_higher_sun_a_shorter_one() {
        // The built-in sky: a sun 40° high carrying most of the light, over a sky.
        let e = shadow_light_elevation(&EnvMap::sky()).unwrap().to_degrees();
        // The sky's light from lower than the sun is under a tenth of the ground's:
        // the sun sets the reach (its disc is 2° in radius).
        assert!((37.0..=41.0).contains(&e), "{e}°");
        let reach = shadow_reach(40f32.to_radians(), NOMINAL_SUBJECT);
        assert!((reach - (0.4 + 1.9 / 40f32.to_radians().tan())).abs() < 1e-5);
        assert!(shadow_reach(60f32.to_radians(), NOMINAL_SUBJECT) < reach);
        // A uniform sky: the lights are spread down to the horizon.
        let uniform = shadow_light_elevation(&EnvMap::uniform([1.0; 3], 32)).unwrap();
        assert!(uniform.to_degrees() < 20.0, "{}°", uniform.to_degrees());
        assert!(shadow_light_elevation(&EnvMap::uniform([0.0; 3], 8)).is_none());
        // The patch's fade begins where the shadow ends.
        assert!((patch_side_holding(2.0) * 0.5 * EDGE_FADE_FROM - 2.0).abs() < 1e-5);
    }
}
