//! The truth of several walkers at once: the stage's unperturbed walker placed several
//! times in one world, each by its own rigid placement, at its own instant of its walk,
//! shaded by its own lights, seen through one camera with true occlusion between them
//! (the nearest hit wins) and true shadows on one another (every shadow ray tests every
//! walker); and the true relative irradiance of the ground among them. What a scene of
//! several relit walkers should look like, against which a composite of fields is judged.
//!
//! Lights are given per walker because a relit field is lit per walker (each in its own
//! frame, by its own environment or sun); for one shared world light, give every walker
//! the same list.

use frf_core::camera::{Camera, Rigid};
use frf_core::image::{GrayImage, Rgb, RgbImage};
use frf_core::light::DirLight;
use glam::Vec3;

use crate::actor::Actor;
use crate::ground::relative_irradiance_among;
use crate::render::{Lit, render_crowd};
use crate::stage::Stage;
use crate::studio::Illumination;

/// One walker of a crowd.
#[derive(Debug, Clone, PartialEq)]
pub struct Walker {
    /// Where its subject frame (treadmill at `y = 0`, facing `+x`) lies in the world;
    /// keep `+y` up, or its feet leave the ground.
    pub world_from_subject: Rigid,
    /// Seconds into its walk (any value; the walk repeats every cycle).
    pub time_s: f64,
    /// The directional lights (world frame) that shade it.
    pub lights: Vec<DirLight>,
}

/// A crowd's true image: premultiplied colour on black, total coverage and each walker's.
#[derive(Debug, Clone)]
pub struct CrowdTruth {
    /// Premultiplied linear colour.
    pub color: RgbImage,
    /// Coverage by any walker.
    pub alpha: GrayImage,
    /// Per walker, in the order given, the fraction of each pixel whose nearest hit is
    /// that walker; they sum to `alpha`.
    pub coverage: Vec<GrayImage>,
}

impl Stage {
    /// The unperturbed walkers of `walkers`, each posed at its instant and placed in the
    /// world.
    pub fn crowd_actors(&self, walkers: &[Walker]) -> Vec<Actor> {
        walkers
            .iter()
            .map(|w| {
                self.actor(None, w.time_s)
                    .transformed(&w.world_from_subject)
            })
            .collect()
    }

    /// The true image of `walkers` seen by `camera` (world frame), without studio or
    /// noise, supersampled and blurred as every stage image. A crowd of one at the
    /// identity placement is [`Stage::truth_image_at`].
    pub fn crowd_truth(&self, camera: &Camera, walkers: &[Walker]) -> CrowdTruth {
        let actors = self.crowd_actors(walkers);
        let illuminations: Vec<Illumination> = walkers
            .iter()
            .map(|w| Illumination::Lights(w.lights.clone()))
            .collect();
        let lit: Vec<Lit> = actors
            .iter()
            .zip(&illuminations)
            .map(|(actor, illumination)| Lit {
                actor,
                illumination,
            })
            .collect();
        let r = render_crowd(camera, &lit, self.config().samples_per_axis);
        CrowdTruth {
            color: r.color,
            alpha: r.alpha,
            coverage: r.coverage,
        }
    }

    /// The true relative irradiance of the ground at world point `point` (on `y = 0`)
    /// under `lights` (world frame), with every walker of `walkers` in the way
    /// ([`crate::ground`]'s definition).
    pub fn crowd_ground_irradiance(
        &self,
        walkers: &[Walker],
        lights: &[DirLight],
        point: Vec3,
    ) -> Rgb {
        relative_irradiance_among(&self.crowd_actors(walkers), lights, point)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Preset, StageConfig};

    fn stage() -> Stage {
        Stage::new(StageConfig::preset(Preset::Tiny)).expect("the tiny preset is valid")
    }

    fn at(x: f32, z: f32) -> Rigid {
        Rigid {
            rotation: glam::Mat3::IDENTITY,
            translation: Vec3::new(x, 0.0, z),
        }
    }

    fn camera(eye: Vec3, width: u32, height: u32) -> Camera {
        Camera::look_at(
            eye,
            Vec3::new(0.0, 0.9, 0.0),
            Vec3::Y,
            30f32.to_radians(),
            width,
            height,
        )
        .expect("a valid camera")
    }

    fn sun() -> Vec<DirLight> {
        vec![DirLight {
            direction: Vec3::new(1.0, 0.2, 0.0).normalize(),
            irradiance: [3.0, 2.8, 2.5],
        }]
    }

    #[test]
    fn a_crowd_of_one_is_the_truth_image() {
        let stage = stage();
        let cam = camera(Vec3::new(0.5, 1.2, 4.0), 48, 64);
        let lights = sun();
        for t in [0.0, 0.37] {
            let one = stage.crowd_truth(
                &cam,
                &[Walker {
                    world_from_subject: Rigid::IDENTITY,
                    time_s: t,
                    lights: lights.clone(),
                }],
            );
            let truth = stage.truth_image_at(t, &cam, &lights);
            assert_eq!(one.color.pixels(), truth.color.pixels());
            assert_eq!(one.alpha.pixels(), truth.alpha.pixels());
            assert_eq!(one.coverage[0].pixels(), truth.alpha.pixels());
        }
    }

    #[test]
    fn the_nearer_walker_hides_the_farther() {
        let stage = stage();
        // The camera on +z looks toward -z: walker 0 stands 1 m nearer than walker 1,
        // a little to the side, so they overlap in part.
        let cam = camera(Vec3::new(0.0, 1.0, 5.0), 96, 96);
        let walker = |x, z, t| Walker {
            world_from_subject: at(x, z),
            time_s: t,
            lights: sun(),
        };
        let crowd = [walker(0.1, 1.0, 0.2), walker(-0.1, 0.0, 0.6)];
        let both = stage.crowd_truth(&cam, &crowd);
        let far_alone = stage.crowd_truth(&cam, &crowd[1..]);
        let (near, far) = (&both.coverage[0], &both.coverage[1]);
        let mut hidden = 0;
        for i in 0..near.pixels().len() {
            let (n, f) = (near.pixels()[i], far.pixels()[i]);
            let sum = n + f;
            assert!((sum - both.alpha.pixels()[i]).abs() < 1e-5, "pixel {i}");
            // Where the near walker covers the pixel, the far one is not seen, though
            // alone it would be.
            if n > 0.999 && far_alone.coverage[0].pixels()[i] > 0.99 {
                assert!(
                    f < 1e-3,
                    "pixel {i}: far walker seen through the near ({f})"
                );
                hidden += 1;
            }
        }
        assert!(hidden > 20, "the walkers overlap in {hidden} pixels only");
        // Where the far walker is seen, the image is what it shows alone.
        assert!(far.pixels().iter().any(|&f| f > 0.999));
    }

    #[test]
    fn a_walker_between_the_sun_and_another_shades_it() {
        let stage = stage();
        // The sun is low in +x (11° up); walker 0 stands 1.2 m toward it from walker 1,
        // whose surface up to about 1.5 m falls in its shadow. The camera on +z frames
        // walker 1.
        let cam = camera(Vec3::new(-0.3, 1.0, 4.0), 64, 96);
        let walker = |x, t| Walker {
            world_from_subject: at(x, 0.0),
            time_s: t,
            lights: sun(),
        };
        let crowd = [walker(1.2, 0.1), walker(0.0, 0.5)];
        let both = stage.crowd_truth(&cam, &crowd);
        let alone = stage.crowd_truth(&cam, &crowd[1..]);
        let (mut with, mut without, mut pixels, mut darker) = (0.0f64, 0.0f64, 0, 0);
        for i in 0..both.alpha.pixels().len() {
            // Pixels of walker 1 alone in both images.
            if both.coverage[1].pixels()[i] > 0.99 && alone.coverage[0].pixels()[i] > 0.99 {
                let (a, b) = (
                    both.color.pixels()[i].iter().sum::<f32>(),
                    alone.color.pixels()[i].iter().sum::<f32>(),
                );
                assert!(a <= b + 1e-6, "pixel {i} brighter with a walker in the way");
                with += f64::from(a);
                without += f64::from(b);
                pixels += 1;
                darker += usize::from(a < 0.5 * b);
            }
        }
        assert!(pixels > 50 && without > 0.0);
        assert!(
            with < 0.7 * without,
            "shaded {with} against {without} alone"
        );
        assert!(
            darker * 3 > pixels,
            "{darker} of {pixels} pixels in the shadow"
        );
        // The ground between them is shadowed by walker 0 only when it is present.
        let lights = sun();
        let point = Vec3::new(0.7, 0.0, 0.0);
        let hit = (0..40).map(|k| point + Vec3::new(0.0, 0.0, 0.01 * k as f32 - 0.2));
        let shadowed: Vec<Vec3> = hit
            .filter(|p| stage.crowd_ground_irradiance(&crowd[..1], &lights, *p)[0] == 0.0)
            .collect();
        assert!(!shadowed.is_empty());
        for p in shadowed {
            assert_eq!(stage.crowd_ground_irradiance(&crowd, &lights, p)[0], 0.0);
            assert_eq!(
                stage.crowd_ground_irradiance(&crowd[1..], &lights, p),
                [1.0; 3]
            );
        }
    }
}
