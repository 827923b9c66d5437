//! Recording a camera move: keys set while moving (the camera at the scene time when the
//! key was set) become the camera path of a scene file (`frf view ... --record
//! shot.toml`) that `frf render shot.toml` renders. The file carries what the viewer
//! shows besides: field, frame size, exposure, interpolation, the lighting (its keys, or
//! the environment, yaw and intensity the viewer set), floor, backdrop, shadow and the
//! walkers. Its time range runs from the first key to one frame past the last, at the
//! scene's rate: a key set a whole number of frames after the first is exactly a frame
//! (set keys while the walk plays, or step it pose by pose, and the frames fall between).
//! Paths are absolute: the file renders from any directory.

use std::path::Path;

use frf_core::env::EnvSource;
use frf_reflectance::project::FloorModel;
use frf_render::composite::GroundLook;
use frf_scene::file::{
    CameraToml, CompositeToml, InstanceToml, LightKeyToml, LightingToml, OutputToml, ProbeToml,
    SceneToml, SunToml, TimeToml, written,
};
use frf_scene::path::Key;
use frf_scene::{BackdropSpec, Scene, ShadowSpec};

use crate::ViewError;

/// The keys recorded so far, in time order; a key set at the time of another replaces it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Recording {
    keys: Vec<Key>,
}

impl Recording {
    /// Adds `key` (replacing one at the same time).
    pub fn add(&mut self, key: Key) {
        self.keys.retain(|k| k.time != key.time);
        let at = self.keys.partition_point(|k| k.time < key.time);
        self.keys.insert(at, key);
    }

    /// The keys, in time order.
    pub fn keys(&self) -> &[Key] {
        &self.keys
    }
}

/// `path` made absolute (resolved where it exists), as text.
fn absolute(path: &Path) -> String {
    let p = path.canonicalize().unwrap_or_else(|_| {
        std::env::current_dir()
            .map(|d| d.join(path))
            .unwrap_or_else(|_| path.to_path_buf())
    });
    p.display().to_string()
}

fn env_text(env: &EnvSource) -> String {
    match env {
        EnvSource::File(p) => absolute(p),
        other => other.to_string(),
    }
}

/// The scene file of `recording` over `scene` on `field`, frames of `size`, exposed by
/// `exposure` stops; and a note when the backdrop had to change (a plate is seen by one
/// camera only).
pub fn scene_toml(
    scene: &Scene,
    field: &Path,
    recording: &Recording,
    size: (u32, u32),
    exposure: f32,
) -> Result<(String, Option<String>), ViewError> {
    let keys = recording.keys();
    let (Some(first), Some(last)) = (keys.first(), keys.last()) else {
        return Err(ViewError::NothingRecorded);
    };
    let fps = scene.fps;
    let base = &scene.lighting[0];
    let mut note = None;
    let (backdrop, ground, plate) = match &scene.backdrop {
        BackdropSpec::None => ("none", None, None),
        BackdropSpec::Environment(g) => (
            "env",
            match g {
                GroundLook::Environment => None,
                GroundLook::Albedo(a) => Some(toml::Value::Array(
                    a.iter().map(|&v| toml::Value::Float(v.into())).collect(),
                )),
            },
            None,
        ),
        BackdropSpec::Plate(p) if keys.len() == 1 => ("plate", None, Some(absolute(p))),
        BackdropSpec::Plate(_) => {
            note = Some(
                "the plate is seen by one camera only: the recorded move of several keys has no backdrop"
                    .to_string(),
            );
            ("none", None, None)
        }
    };
    let out = SceneToml {
        field: Some(written(absolute(field))),
        time: written(TimeToml {
            start: written(first.time),
            // One frame past the last key, so that it is a frame too; a single key is a
            // still.
            end: written(if keys.len() > 1 {
                last.time + 1.0 / fps
            } else {
                first.time
            }),
            fps: written(fps),
            interpolate: scene.interpolate.map(|i| written(i.name().to_string())),
        }),
        output: OutputToml {
            size: Some(written(vec![size.0, size.1])),
            exposure: written(exposure),
            layers: scene.layers,
            preview: written(scene.preview.name().to_string()),
            variant: written(scene.variant.name().to_string()),
        },
        lighting: written(LightingToml {
            env: Some(written(env_text(&base.env))),
            yaw_deg: written(base.yaw_deg),
            intensity: written(base.intensity),
            floor: written(
                match scene.floor {
                    FloorModel::Environment => "env",
                    FloorModel::LambertianGround { .. } => "ground",
                }
                .to_string(),
            ),
            key: scene.lighting[1..]
                .iter()
                .map(|k| {
                    written(LightKeyToml {
                        time: written(k.time),
                        env: Some(written(env_text(&k.env))),
                        yaw_deg: Some(written(k.yaw_deg)),
                        intensity: Some(written(k.intensity)),
                    })
                })
                .collect(),
            sun: scene.sun.map(|sun| {
                let e = sun.illuminance();
                let strength = e[0].max(e[1]).max(e[2]);
                written(SunToml {
                    azimuth_deg: None,
                    elevation_deg: None,
                    direction: Some(sun.direction().to_array()),
                    angular_diameter_deg: Some(2.0 * sun.radius().to_degrees()),
                    illuminance: Some(strength),
                    radiance: None,
                    colour: (strength > 0.0).then(|| e.map(|c| c / strength)),
                })
            }),
            probe: scene
                .probes
                .iter()
                .flat_map(|p| &p.probes)
                .map(|p| {
                    written(ProbeToml {
                        position: p.position.to_array(),
                        env: env_text(&p.env),
                        yaw_deg: f64::from(p.yaw).to_degrees(),
                        intensity: p.intensity,
                        suns: p.suns,
                    })
                })
                .collect(),
        }),
        camera: written(CameraToml {
            orbit: None,
            key: keys.iter().map(|k| written(*k)).collect(),
        }),
        composite: CompositeToml {
            backdrop: written(backdrop.to_string()),
            ground: ground.map(written),
            shadow: written(
                match scene.shadow {
                    ShadowSpec::Maps => "maps",
                    ShadowSpec::Traced => "traced",
                    ShadowSpec::None => "none",
                }
                .to_string(),
            ),
            plate: plate.map(written),
        },
        instance: scene
            .instances
            .iter()
            .map(|i| written(InstanceToml::of(i)))
            .collect(),
    };
    let text = toml::to_string(&out).map_err(|e| ViewError::Record(e.to_string()))?;
    Ok((
        format!(
            "# Recorded by `frf view`: render with `frf render {{this file}} --out DIR`.\n{text}"
        ),
        note,
    ))
}

/// Writes the scene file of `recording` to `path` atomically; the note of
/// [`scene_toml`], if any.
pub fn write(
    path: &Path,
    scene: &Scene,
    field: &Path,
    recording: &Recording,
    size: (u32, u32),
    exposure: f32,
) -> Result<Option<String>, ViewError> {
    let (text, note) = scene_toml(scene, field, recording, size, exposure)?;
    frf_core::atomic::write_atomic(path, |w| {
        use std::io::Write;
        w.write_all(text.as_bytes())
            .map_err(|e| frf_core::CoreError::io(path, e))
    })?;
    Ok(note)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = r#"
[time]
end = 2.0
fps = 12.0
interpolate = "nearest"

[output]
variant = "linear"
preview = "gif"
layers = true

[lighting]
env = "sky"
yaw_deg = 30.0
intensity = 1.5
floor = "ground"
[[lighting.key]]
time = 1.0
env = "uniform"
yaw_deg = 90.0

[camera]
orbit = { radius = 3.0, height = 1.4, start_deg = 0.0, sweep_deg = 90.0, look_at = [0.0, 0.9, 0.0], fov_deg = 35.0 }

[composite]
backdrop = "env"
ground = [0.3, 0.25, 0.2]
shadow = "traced"

[[instance]]
position = [0.0, 0.0, 0.0]
[[instance]]
position = [1.0, 0.0, -0.5]
heading_deg = 90.0
time_offset = 0.25
"#;

    fn key(time: f64, x: f32) -> Key {
        Key {
            time,
            position: [x, 1.4, 3.0],
            look_at: [0.0, 0.9, 0.0],
            fov_deg: 30.0,
        }
    }

    #[test]
    fn a_recorded_scene_reads_back_as_the_scene_with_the_keys() {
        let dir = tempfile::tempdir().expect("a directory");
        let scene = Scene::parse(&dir.path().join("s.toml"), SCENE).expect("a scene");
        let mut rec = Recording::default();
        rec.add(key(0.5, 1.0));
        rec.add(key(0.0, 2.0));
        rec.add(key(0.5, 3.0)); // replaces the key at 0.5
        assert_eq!(rec.keys().len(), 2);
        let field = dir.path().join("walker.frf");
        let (text, note) = scene_toml(&scene, &field, &rec, (64, 48), 1.0).expect("text");
        assert!(note.is_none());
        let back = Scene::parse(&dir.path().join("shot.toml"), &text).expect("it parses");
        assert_eq!(back.field.as_deref(), Some(field.as_path()));
        assert_eq!(
            (back.start, back.end, back.fps),
            (0.0, 0.5 + 1.0 / 12.0, 12.0)
        );
        assert_eq!(back.size, Some((64, 48)));
        assert_eq!(back.exposure, 1.0);
        assert_eq!(back.variant, scene.variant);
        assert_eq!(
            (back.preview, back.layers, back.interpolate),
            (scene.preview, scene.layers, scene.interpolate)
        );
        assert_eq!(back.lighting, scene.lighting);
        assert_eq!(back.floor, scene.floor);
        assert_eq!(back.backdrop, scene.backdrop);
        assert_eq!(back.shadow, scene.shadow);
        assert_eq!(back.instances.len(), 2);
        for (a, b) in back.instances.iter().zip(&scene.instances) {
            assert_eq!(a.position, b.position);
            assert!((a.heading - b.heading).abs() < 1e-6);
            assert_eq!(a.time_offset, b.time_offset);
        }
        let frf_scene::path::Trajectory::Path(p) = &back.camera else {
            panic!("keys become a path");
        };
        assert_eq!(p.keys, vec![key(0.0, 2.0), key(0.5, 3.0)]);
        // Nothing recorded: refused.
        let empty = scene_toml(&scene, &field, &Recording::default(), (64, 48), 0.0);
        assert!(matches!(empty, Err(ViewError::NothingRecorded)));
    }
}
