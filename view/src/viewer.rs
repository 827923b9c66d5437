//! What the viewer shows and every change to it, without a window: the live shot
//! ([`Shot::live`]), the camera, the scene's clock, the light, what is drawn, the keys
//! recorded. Keys, mouse, the panel and scripts all change it through these methods, so
//! that a script does exactly what a person does.

use std::path::{Path, PathBuf};

use frf_core::camera::Camera;
use frf_core::env::EnvSource;
use frf_reflectance::container::FileSource;
use frf_render::composite::GroundLook;
use frf_render::gpu::present::ShownLayer;
use frf_render::morph::Variant;
use frf_scene::path::Trajectory;
use frf_scene::shot::Shot;
use frf_scene::{BackdropSpec, LightKey, ShadowSpec};
use glam::Vec3;

use crate::ViewError;
use crate::camera::{ViewCamera, nearest_view};
use crate::record::Recording;
use crate::script::Command;

/// The backdrops a viewer offers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BackdropChoice {
    /// Transparent.
    None,
    /// The environment.
    Env,
    /// The scene's plate.
    Plate,
}

impl BackdropChoice {
    /// Its name in menus and scripts.
    pub fn name(self) -> &'static str {
        match self {
            BackdropChoice::None => "none",
            BackdropChoice::Env => "env",
            BackdropChoice::Plate => "plate",
        }
    }
}

/// The viewer's state (see the module docs).
pub struct Viewer<'a> {
    /// The scene drawn, on its field.
    pub shot: Shot<'a, FileSource>,
    /// The field's path (for a recorded scene).
    pub field_path: PathBuf,
    /// The camera.
    pub camera: ViewCamera,
    /// Seconds of the scene's clock.
    pub time: f64,
    /// Whether the walk plays.
    pub playing: bool,
    /// What is shown of a frame.
    pub layer: ShownLayer,
    /// Stops.
    pub exposure: f32,
    /// The environments offered (the files given, the built-in sky, ...).
    pub envs: Vec<EnvSource>,
    /// The environment chosen among them; `None` while the scene's own lighting is kept.
    pub env: Option<usize>,
    /// Degrees (of the lighting's first key while the scene's is kept).
    pub yaw_deg: f32,
    /// Multiplier.
    pub intensity: f32,
    /// The scene's shadow when on (maps unless it asked for traced).
    shadow_when_on: ShadowSpec,
    /// The ground of an environment backdrop.
    ground: GroundLook,
    /// The scene's plate, if it has one.
    plate: Option<PathBuf>,
    /// The keys recorded.
    pub recording: Recording,
    /// Where the clock loops: `[start, end)`.
    pub span: (f64, f64),
    /// Whether the walkers' paths are drawn over the frame ([`crate::paths`]).
    pub show_paths: bool,
}

impl<'a> Viewer<'a> {
    /// A viewer of `shot` (a live shot), its camera where the scene's starts, offering
    /// `envs`.
    pub fn new(shot: Shot<'a, FileSource>, field_path: PathBuf, envs: Vec<EnvSource>) -> Self {
        let scene = shot.scene().clone();
        let h = shot.field().header();
        let (start, end) = if scene.end > scene.start {
            (scene.start, scene.end)
        } else {
            (scene.start, scene.start + h.cycle_seconds)
        };
        let key = match &scene.camera {
            Trajectory::Path(p) => p.at(start),
            Trajectory::Orbit(o) => o.key(0.0),
        };
        let camera = ViewCamera::looking(
            Vec3::from(key.position),
            Vec3::from(key.look_at),
            key.fov_deg,
        )
        .unwrap_or(ViewCamera {
            target: Vec3::new(0.0, 0.9, 0.0),
            distance: 3.0,
            azimuth: 0.0,
            elevation: 0.1,
            fov_deg: 35.0,
        });
        let base = &scene.lighting[0];
        let mut envs = envs;
        for e in scene.environments() {
            if e != EnvSource::None && !envs.contains(&e) {
                envs.push(e);
            }
        }
        Self {
            field_path,
            camera,
            time: start,
            playing: false,
            layer: ShownLayer::Composite,
            exposure: scene.exposure,
            envs,
            env: None,
            yaw_deg: frf_core::light::within_half_turn(base.yaw_deg) as f32,
            intensity: base.intensity,
            shadow_when_on: match scene.shadow {
                ShadowSpec::Traced => ShadowSpec::Traced,
                _ => ShadowSpec::Maps,
            },
            ground: match scene.backdrop {
                BackdropSpec::Environment(g) => g,
                _ => GroundLook::Environment,
            },
            plate: match &scene.backdrop {
                BackdropSpec::Plate(p) => Some(p.clone()),
                _ => None,
            },
            recording: Recording::default(),
            span: (start, end),
            shot,
            show_paths: true,
        }
    }

    /// Seconds between two poses of the walk.
    pub fn pose_seconds(&self) -> f64 {
        let h = self.shot.field().header();
        h.cycle_seconds / f64::from(h.poses_per_cycle.max(1))
    }

    /// Sets the clock to `t`, looped into the span.
    pub fn set_time(&mut self, t: f64) {
        let (a, b) = self.span;
        self.time = if t.is_finite() && b > a {
            a + (t - a).rem_euclid(b - a)
        } else {
            a
        };
    }

    /// Advances the clock by `seconds` of real time while playing.
    pub fn advance(&mut self, seconds: f32) {
        if self.playing {
            self.set_time(self.time + f64::from(seconds));
        }
    }

    /// Steps the walk `poses` poses forward (negative: back).
    pub fn step(&mut self, poses: i32) {
        self.set_time(self.time + f64::from(poses) * self.pose_seconds());
    }

    /// The poses the walkers show now.
    pub fn poses(&self) -> Vec<u32> {
        self.shot.poses_at(self.time)
    }

    /// The captured cameras of the first walker's pose now, in the scene frame (its
    /// subject frame placed where it stands), with their grid index `(column, row)`.
    pub fn captured_views(&self) -> Vec<((usize, usize), Camera)> {
        let h = self.shot.field().header();
        let pose = self.poses()[0];
        let Some(record) = h.poses.iter().find(|p| p.pose == pose) else {
            return Vec::new();
        };
        let world = self
            .shot
            .scene()
            .placement(0, self.time)
            .world_from_subject();
        let mut out = Vec::new();
        for u in 0..h.columns {
            for v in 0..h.rows {
                let Some(view) = record.views.get(h.view_index(u, v)) else {
                    continue;
                };
                if let Ok(c) = view.camera.to_camera() {
                    out.push(((u, v), c.transformed(&world)));
                }
            }
        }
        out
    }

    /// The axis of the first walker (where it stands now).
    fn axis_at(&self) -> Vec3 {
        self.shot.scene().placement(0, self.time).position
    }

    /// Puts the camera at captured view `(column, row)`.
    pub fn view(&mut self, column: usize, row: usize) -> Result<(), ViewError> {
        let views = self.captured_views();
        let (_, c) = views
            .iter()
            .find(|(k, _)| *k == (column, row))
            .ok_or_else(|| {
                let h = self.shot.field().header();
                ViewError::Bad(format!(
                    "no captured view ({column}, {row}): the grid has {} columns and {} rows",
                    h.columns, h.rows
                ))
            })?;
        self.camera = ViewCamera::of_camera(c, self.axis_at())
            .ok_or_else(|| ViewError::Bad("a captured camera without a direction".into()))?;
        Ok(())
    }

    /// Puts the camera at the captured view of the first column's middle row.
    pub fn reset(&mut self) -> Result<(), ViewError> {
        let rows = self.shot.field().header().rows;
        self.view(0, rows / 2)
    }

    /// Puts the camera at the captured view nearest it.
    pub fn snap(&mut self) -> Result<(), ViewError> {
        let views = self.captured_views();
        let cameras: Vec<Camera> = views.iter().map(|(_, c)| *c).collect();
        let Some(k) = nearest_view(&cameras, self.camera.position(), self.axis_at()) else {
            return Err(ViewError::Bad("the pose shown has no captured view".into()));
        };
        let (column, row) = views[k].0;
        self.view(column, row)
    }

    /// Lights the scene by environment `index` of [`Viewer::envs`] at the viewer's yaw
    /// and intensity (the scene's keys are dropped); `None` keeps the scene's lighting.
    fn relight(&mut self) -> Result<(), ViewError> {
        let Some(i) = self.env else {
            return Ok(());
        };
        let env = self.envs[i].clone();
        let (yaw_deg, intensity) = (f64::from(self.yaw_deg), self.intensity);
        self.shot.edit(|s| {
            s.lighting = vec![LightKey {
                time: f64::NEG_INFINITY,
                env,
                yaw_deg,
                intensity,
            }];
        })?;
        Ok(())
    }

    /// The environment the scene is lit by now (its first key's).
    pub fn env_index(&self) -> Option<usize> {
        let base = &self.shot.scene().lighting[0].env;
        self.envs.iter().position(|e| e == base)
    }

    /// Lights the scene by environment `index` of [`Viewer::envs`].
    pub fn set_env(&mut self, index: usize) -> Result<(), ViewError> {
        if index >= self.envs.len() {
            return Err(ViewError::Bad(format!("no environment {index}")));
        }
        self.env = Some(index);
        self.relight()
    }

    /// The environment offered whose path, name or word is `name`.
    pub fn env_named(&self, name: &str) -> Result<usize, ViewError> {
        self.envs
            .iter()
            .position(|e| {
                e.to_string() == name
                    || e.name() == name
                    || matches!(e, EnvSource::File(p) if p == Path::new(name))
            })
            .ok_or_else(|| {
                ViewError::Bad(format!(
                    "no environment {name:?} offered (offered: {}; give more with --env)",
                    self.envs
                        .iter()
                        .map(EnvSource::name)
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            })
    }

    /// Turns the light by `yaw_deg` (from the scene's own lighting, the environment of its
    /// first key), kept within ±180° (reduced in double precision).
    pub fn set_yaw(&mut self, yaw_deg: f32) -> Result<(), ViewError> {
        self.yaw_deg = frf_core::light::within_half_turn(f64::from(yaw_deg)) as f32;
        self.take_light()
    }

    /// Scales the light.
    pub fn set_intensity(&mut self, intensity: f32) -> Result<(), ViewError> {
        self.intensity = intensity.max(0.0);
        self.take_light()
    }

    /// The viewer's lighting from now on: the environment shown, turned and scaled.
    fn take_light(&mut self) -> Result<(), ViewError> {
        if self.env.is_none() {
            self.env = self.env_index();
        }
        if self.env.is_none() {
            let now = match self.shot.scene().sun {
                Some(_) => "the field is lit by a sun alone (no environment)",
                None => "the field is shown unlit",
            };
            return Err(ViewError::Bad(format!(
                "{now}: choose an environment first to turn or scale the light"
            )));
        }
        self.relight()
    }

    /// Draws by `variant`.
    pub fn set_variant(&mut self, variant: Variant) -> Result<(), ViewError> {
        self.shot.edit(|s| s.variant = variant)?;
        Ok(())
    }

    /// The backdrop now.
    pub fn backdrop(&self) -> BackdropChoice {
        match self.shot.scene().backdrop {
            BackdropSpec::None => BackdropChoice::None,
            BackdropSpec::Environment(_) => BackdropChoice::Env,
            BackdropSpec::Plate(_) => BackdropChoice::Plate,
        }
    }

    /// The backdrops offered: an environment when the scene is lit, a plate when it has
    /// one.
    pub fn backdrops(&self) -> Vec<BackdropChoice> {
        let lit = self.shot.scene().lighting[0].env != EnvSource::None;
        let mut out = vec![BackdropChoice::None];
        if lit {
            out.push(BackdropChoice::Env);
        }
        if self.plate.is_some() {
            out.push(BackdropChoice::Plate);
        }
        out
    }

    /// Puts the walkers over `choice`.
    pub fn set_backdrop(&mut self, choice: BackdropChoice) -> Result<(), ViewError> {
        if !self.backdrops().contains(&choice) {
            return Err(ViewError::Bad(format!(
                "no {} backdrop here (offered: {})",
                choice.name(),
                self.backdrops()
                    .iter()
                    .map(|b| b.name())
                    .collect::<Vec<_>>()
                    .join(", ")
            )));
        }
        let spec = match choice {
            BackdropChoice::None => BackdropSpec::None,
            BackdropChoice::Env => BackdropSpec::Environment(self.ground),
            BackdropChoice::Plate => BackdropSpec::Plate(self.plate.clone().unwrap_or_default()),
        };
        self.shot.edit(|s| s.backdrop = spec)?;
        Ok(())
    }

    /// Whether the walkers cast their shadow.
    pub fn shadow(&self) -> bool {
        self.shot.scene().shadow != ShadowSpec::None
    }

    /// Turns the shadow on or off.
    pub fn set_shadow(&mut self, on: bool) -> Result<(), ViewError> {
        let spec = if on {
            self.shadow_when_on
        } else {
            ShadowSpec::None
        };
        self.shot.edit(|s| s.shadow = spec)?;
        Ok(())
    }

    /// The frame size the camera draws for a window of `window` pixels: the window's, or
    /// the plate's when the backdrop is a plate.
    pub fn frame_size(&self, window: (u32, u32)) -> Result<(u32, u32), ViewError> {
        if let BackdropSpec::Plate(p) = &self.shot.scene().backdrop {
            let (w, h) = frf_core::io::image_dimensions(p)?;
            return Ok((w as u32, h as u32));
        }
        Ok((window.0.max(1), window.1.max(1)))
    }

    /// Records the camera at the current time.
    pub fn key(&mut self) {
        self.recording.add(self.camera.key(self.time));
    }

    /// Applies a script's command (those that do not wait for a frame).
    pub fn apply(&mut self, command: &Command) -> Result<(), ViewError> {
        match command {
            Command::Camera(p, l, fov) => {
                self.camera = ViewCamera::looking(*p, *l, *fov).ok_or_else(|| {
                    ViewError::Bad(format!("camera at {p} looking at {l}: they coincide"))
                })?;
            }
            Command::View(u, v) => self.view(*u, *v)?,
            Command::Snap => self.snap()?,
            Command::Orbit(a, e) => self.camera.orbit(a.to_radians(), e.to_radians()),
            Command::Dolly(f) => self.camera.dolly(*f),
            Command::Time(t) => self.set_time(*t),
            Command::Step(n) => self.step(*n),
            Command::Play => self.playing = true,
            Command::Pause => self.playing = false,
            Command::Env(name) => {
                let i = self.env_named(name)?;
                self.set_env(i)?;
            }
            Command::Yaw(d) => self.set_yaw(*d)?,
            Command::Intensity(k) => self.set_intensity(*k)?,
            Command::Variant(v) => self.set_variant(*v)?,
            Command::Backdrop(w) => {
                let choice = match w.as_str() {
                    "env" => BackdropChoice::Env,
                    "plate" => BackdropChoice::Plate,
                    _ => BackdropChoice::None,
                };
                self.set_backdrop(choice)?;
            }
            Command::Shadow(on) => self.set_shadow(*on)?,
            Command::Layer(l) => self.layer = *l,
            Command::Exposure(e) => self.exposure = *e,
            Command::Key => self.key(),
            Command::Wait(_) | Command::Screenshot(_) | Command::Quit => {}
        }
        Ok(())
    }

    /// Renders the frame shown (read back) and writes the layer shown to `path`: the
    /// composite, walkers alone or backdrop as `frf render` writes its frames (an 8-bit
    /// sRGB PNG with straight alpha, exposed, or a linear premultiplied EXR), alpha as an
    /// 8-bit grey PNG, the shadow layer as a linear 16-bit PNG or an EXR.
    pub fn screenshot(&mut self, path: &Path, window: (u32, u32)) -> Result<(), ViewError> {
        use frf_core::io;
        let size = self.frame_size(window)?;
        let camera = self.camera.camera(size.0, size.1)?;
        let layers = !matches!(self.layer, ShownLayer::Composite | ShownLayer::Alpha);
        let r = self.shot.render_at(self.time, &camera, layers)?;
        let exr = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
        let scale = 2f32.powf(self.exposure);
        let frame = r.frame;
        let rgba = match (self.layer, &frame.layers) {
            (ShownLayer::Subject, Some(l)) => Some(&l.subject),
            (ShownLayer::Backdrop, Some(l)) => Some(&l.backdrop),
            (ShownLayer::Composite, _) => Some(&frame.composite),
            _ => None,
        };
        match (rgba, self.layer, &frame.layers) {
            (Some(img), _, _) if exr => io::write_exr_rgba(path, img)?,
            (Some(img), _, _) => io::write_png8_srgba(path, img, scale)?,
            (None, ShownLayer::Alpha, _) => {
                let alpha = frame.composite.map(|p| p[3]);
                if exr {
                    io::write_exr_rgb(path, &alpha.map(|a| [a; 3]))?;
                } else {
                    io::write_png8_gray(path, &alpha)?;
                }
            }
            (None, _, Some(l)) if exr => io::write_exr_rgb(path, &l.shadow)?,
            (None, _, Some(l)) => io::write_png16_rgb(path, &l.shadow)?,
            (None, _, None) => return Err(ViewError::Bad("no layers were drawn".into())),
        }
        Ok(())
    }
}
