//! The window and its event loop (winit): the GPU opened for the window's surface, each
//! frame drawn by the live shot into kept targets, shown by the present pass with the
//! panel over it, and submitted once; keys and mouse turned into [`Viewer`] changes; a
//! script's commands run between frames. Closing the window, a lost display and a failed
//! frame end the loop with a message, never a panic.

use std::collections::HashSet;
use std::sync::Arc;
use std::time::Instant;

use frf_reflectance::FieldFile;
use frf_render::gpu::Gpu;
use frf_render::gpu::present::{PresentPass, ShownLayer};
use frf_render::morph::Variant;
use frf_render::renderer::Device;
use frf_scene::shot::{Shot, ShotOptions};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{KeyCode, ModifiersState, PhysicalKey};
use winit::window::{Window, WindowId};

use crate::panel::{self, Figures};
use crate::script::{Command, Line};
use crate::timer::GpuTimer;
use crate::viewer::Viewer;
use crate::{Ended, Outcome, ViewError, ViewOptions};

/// Median-cut lights of a traced shadow, as `frf render`'s default.
const TRACED_LIGHTS: usize = 64;
/// Radians the camera orbits per pixel dragged.
const ORBIT_PER_PX: f32 = 0.008;
/// Fly speed, in distances to the point looked at per second.
const FLY_SPEED: f32 = 0.6;
/// Look speed, radians per second.
const LOOK_SPEED: f32 = 1.2;

/// A script being run.
struct Script {
    path: std::path::PathBuf,
    lines: Vec<Line>,
    next: usize,
    /// Frames still to wait for.
    waiting: u32,
}

/// Everything that lives once the window is open.
struct Live<'a> {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    viewer: Viewer<'a>,
    present: PresentPass,
    egui: egui_winit::State,
    egui_renderer: egui_wgpu::Renderer,
    timer: Option<GpuTimer>,
    adapter: String,
}

/// The walkers' paths over the frame ([`crate::paths`]), behind the panel: each a line,
/// its walker now a dot.
fn draw_paths(ui: &egui::Ui, viewer: &crate::viewer::Viewer, window: (u32, u32)) {
    let Ok(size) = viewer.frame_size(window) else {
        return;
    };
    let Ok(camera) = viewer.camera.camera(size.0, size.1) else {
        return;
    };
    let painter = ui.ctx().layer_painter(egui::LayerId::background());
    let per_point = ui.ctx().pixels_per_point();
    let point = |p: glam::Vec2| egui::pos2(p.x / per_point, p.y / per_point);
    let colour = egui::Color32::from_rgb(255, 200, 40);
    for o in crate::paths::overlays(viewer.shot.scene(), &camera, window, viewer.time) {
        for run in &o.runs {
            let line: Vec<egui::Pos2> = run.iter().map(|&p| point(p)).collect();
            painter.add(egui::Shape::line(line, egui::Stroke::new(1.5, colour)));
        }
        if let Some(now) = o.now {
            painter.circle_filled(point(now), 4.0, colour);
        }
    }
}

impl Live<'_> {
    fn gpu(&self) -> &Gpu {
        match self.viewer.shot.render_device() {
            Device::Gpu(g) => g,
            Device::Cpu => unreachable!("the viewer opens a GPU"),
        }
    }

    /// The device and queue the shot draws with (the viewer opens a GPU).
    fn device_and_queue(&self) -> (wgpu::Device, wgpu::Queue) {
        match self.viewer.shot.render_device() {
            Device::Gpu(g) => (g.device().clone(), g.queue().clone()),
            Device::Cpu => unreachable!("the viewer opens a GPU"),
        }
    }

    /// Records the panel (when `figures` are given: the panel is shown) over the frame in
    /// `view`, a window of `window_size`; what the person asked for, the command buffers
    /// egui needs submitted first, and whether egui wants another frame at once.
    fn draw_panel(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        view: &wgpu::TextureView,
        window_size: (u32, u32),
        figures: Option<&Figures>,
        message: &mut Option<String>,
    ) -> (panel::Actions, Vec<wgpu::CommandBuffer>, bool) {
        let input = self.egui.take_egui_input(&self.window);
        let mut actions = panel::Actions::default();
        let viewer = &mut self.viewer;
        let mut output = self.egui.egui_ctx().clone().run_ui(input, |ui| {
            if viewer.show_paths {
                draw_paths(ui, viewer, window_size);
            }
            if let Some(figures) = figures {
                actions = panel::show(ui, viewer, figures, message);
            }
        });
        self.egui
            .handle_platform_output(&self.window, output.platform_output);
        let pixels_per_point = output.pixels_per_point;
        let jobs = self
            .egui
            .egui_ctx()
            .tessellate(output.shapes, pixels_per_point);
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [window_size.0, window_size.1],
            pixels_per_point,
        };
        let (device, queue) = self.device_and_queue();
        // Every texture change is applied (egui checks that none is dropped unapplied).
        let mut textures = std::mem::take(&mut output.textures_delta);
        for (id, deltas) in textures.set.drain() {
            for delta in &deltas {
                self.egui_renderer
                    .update_texture(&device, &queue, id, delta);
            }
        }
        let extra = self
            .egui_renderer
            .update_buffers(&device, &queue, encoder, &jobs, &screen);
        {
            let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("panel"),
                color_attachments: &[frf_render::gpu::bind::loaded(view)],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            self.egui_renderer
                .render(&mut pass.forget_lifetime(), &jobs, &screen);
        }
        for id in textures.free.drain() {
            self.egui_renderer.free_texture(&id);
        }
        let repaint_now = output
            .viewport_output
            .get(&egui::ViewportId::ROOT)
            .is_some_and(|v| v.repaint_delay.is_zero());
        (actions, extra, repaint_now)
    }
}

/// The application: options until the window opens, then the live viewer.
struct App<'a> {
    field: &'a FieldFile,
    options: Option<ViewOptions>,
    record: Option<std::path::PathBuf>,
    live: Option<Live<'a>>,
    script: Option<Script>,
    error: Option<ViewError>,
    ended: Option<Ended>,
    /// Messages shown in the panel (a refused change).
    message: Option<String>,
    show_panel: bool,
    held: HashSet<KeyCode>,
    modifiers: ModifiersState,
    drag: Option<(MouseButton, (f64, f64))>,
    cursor: (f64, f64),
    last_frame: Option<Instant>,
    frames: u64,
    gpu_ms: Vec<f64>,
    frame_ms: Vec<f64>,
    screenshots: Vec<std::path::PathBuf>,
    screenshot_count: usize,
}

/// Opens the window and runs the viewer (see [`crate::run`]).
pub(crate) fn run(mut options: ViewOptions) -> Result<Outcome, ViewError> {
    if std::env::var_os("DISPLAY").is_none() && std::env::var_os("WAYLAND_DISPLAY").is_none() {
        return Err(ViewError::NoDisplay(
            "neither DISPLAY nor WAYLAND_DISPLAY is set".into(),
        ));
    }
    let field = FieldFile::open(&options.field)?;
    let event_loop = EventLoop::new().map_err(|e| ViewError::NoDisplay(e.to_string()))?;
    let script = options.script.take().map(|(path, lines)| Script {
        path,
        lines,
        next: 0,
        waiting: 0,
    });
    let mut app = App {
        field: &field,
        record: options.record.clone(),
        options: Some(options),
        live: None,
        script,
        error: None,
        ended: None,
        message: None,
        show_panel: true,
        held: HashSet::new(),
        modifiers: ModifiersState::empty(),
        drag: None,
        cursor: (0.0, 0.0),
        last_frame: None,
        frames: 0,
        gpu_ms: Vec::new(),
        frame_ms: Vec::new(),
        screenshots: Vec::new(),
        screenshot_count: 0,
    };
    let ran = event_loop.run_app(&mut app);
    if let Some(e) = app.error.take() {
        return Err(e);
    }
    ran.map_err(|e| ViewError::Window(e.to_string()))?;
    let Some(live) = app.live.take() else {
        return Err(ViewError::Window(
            "the event loop ended before the window opened".into(),
        ));
    };
    let recorded = match &app.record {
        Some(path) => {
            let v = &live.viewer;
            let size = v.frame_size((live.config.width, live.config.height))?;
            let note = crate::record::write(
                path,
                v.shot.scene(),
                &v.field_path,
                &v.recording,
                size,
                v.exposure,
            )?;
            Some((path.clone(), v.recording.keys().len(), note))
        }
        None => None,
    };
    Ok(Outcome {
        ended: app.ended.unwrap_or(Ended::Quit),
        frames: app.frames,
        gpu_ms: app.gpu_ms,
        frame_ms: app.frame_ms,
        screenshots: app.screenshots,
        recorded,
        residency: (
            live.viewer.shot.counters().poses_made_resident,
            live.viewer.shot.counters().residency_seconds,
        ),
        adapter: live.adapter,
    })
}

impl<'a> App<'a> {
    /// Opens the window, the GPU for its surface, the live shot and the panel.
    fn open(&mut self, event_loop: &ActiveEventLoop) -> Result<(), ViewError> {
        let Some(options) = self.options.take() else {
            return Ok(());
        };
        let title = format!("frf view — {}", options.field.display());
        let attributes = Window::default_attributes()
            .with_title(title)
            .with_inner_size(PhysicalSize::new(options.size.0, options.size.1));
        let window = Arc::new(
            event_loop
                .create_window(attributes)
                .map_err(|e| ViewError::Window(format!("opening the window: {e}")))?,
        );
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
                Box::new(event_loop.owned_display_handle()),
            ));
        let surface = instance
            .create_surface(window.clone())
            .map_err(|e| ViewError::Window(format!("a surface for the window: {e}")))?;
        let gpu = Gpu::on(&instance, Some(&surface))?;
        let size = window.inner_size();
        let mut config = surface
            .get_default_config(gpu.wgpu_adapter(), size.width.max(1), size.height.max(1))
            .ok_or_else(|| ViewError::Window("the adapter cannot present to the window".into()))?;
        config.present_mode = if options.no_vsync {
            wgpu::PresentMode::AutoNoVsync
        } else {
            wgpu::PresentMode::AutoVsync
        };
        surface.configure(gpu.device(), &config);
        let present = PresentPass::new(&gpu, config.format);
        let egui_renderer = egui_wgpu::Renderer::new(
            gpu.device(),
            config.format,
            egui_wgpu::RendererOptions::default(),
        );
        let timer = GpuTimer::new(gpu.device(), gpu.queue());
        let adapter = gpu.adapter().to_string();
        let max_side = gpu.max_texture_side() as usize;
        let shot = Shot::live(
            options.scene,
            self.field,
            Device::Gpu(Box::new(gpu)),
            ShotOptions {
                memory_budget: options.memory_budget,
                planned: false,
                traced_lights: TRACED_LIGHTS,
                detail: None,
                light_tolerance: frf_scene::shot::LightTolerance::DEFAULT,
                walker_shadows: true,
            },
        )?;
        let mut viewer = Viewer::new(shot, options.field.clone(), options.envs);
        if options.start_at_captured_view {
            viewer.reset()?;
        }
        let context = egui::Context::default();
        let egui = egui_winit::State::new(
            context,
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(max_side),
        );
        self.live = Some(Live {
            window,
            surface,
            config,
            viewer,
            present,
            egui,
            egui_renderer,
            timer,
            adapter,
        });
        Ok(())
    }

    /// Ends the loop with `error`.
    fn fail(&mut self, event_loop: &ActiveEventLoop, error: ViewError) {
        if self.error.is_none() {
            self.error = Some(error);
        }
        event_loop.exit();
    }

    /// Runs the script's commands due before the next frame.
    fn run_script_before(&mut self) -> Result<(), ViewError> {
        let (Some(script), Some(live)) = (&mut self.script, &mut self.live) else {
            return Ok(());
        };
        if script.waiting > 0 {
            return Ok(());
        }
        while let Some(line) = script.lines.get(script.next) {
            if line.command.after_a_frame() {
                break;
            }
            live.viewer
                .apply(&line.command)
                .map_err(|e| ViewError::ScriptFailed {
                    path: script.path.clone(),
                    line: line.line,
                    source: Box::new(e),
                })?;
            script.next += 1;
        }
        Ok(())
    }

    /// Runs the script's command due after a frame; whether the viewer should quit.
    fn run_script_after(&mut self) -> Result<bool, ViewError> {
        let (Some(script), Some(live)) = (&mut self.script, &mut self.live) else {
            return Ok(false);
        };
        if script.waiting > 0 {
            script.waiting -= 1;
            return Ok(false);
        }
        let Some(line) = script.lines.get(script.next) else {
            // A script that ends without `quit` ends the viewer too.
            return Ok(true);
        };
        let failed = |e: ViewError| ViewError::ScriptFailed {
            path: script.path.clone(),
            line: line.line,
            source: Box::new(e),
        };
        let quit = match &line.command {
            Command::Wait(n) => {
                script.waiting = n.saturating_sub(1);
                false
            }
            Command::Screenshot(path) => {
                let size = (live.config.width, live.config.height);
                live.viewer.screenshot(path, size).map_err(failed)?;
                self.screenshots.push(path.clone());
                false
            }
            Command::Quit => true,
            _ => false,
        };
        script.next += 1;
        Ok(quit)
    }

    /// Draws and presents one frame.
    fn frame(&mut self, event_loop: &ActiveEventLoop) -> Result<(), ViewError> {
        let now = Instant::now();
        let dt = self
            .last_frame
            .map_or(0.0, |t| now.duration_since(t).as_secs_f32());
        if self.last_frame.is_some() {
            self.frame_ms.push(f64::from(dt) * 1e3);
        }
        self.last_frame = Some(now);
        self.move_with_held_keys(dt);
        self.run_script_before()?;
        let show_panel = self.show_panel;
        let Some(live) = &mut self.live else {
            return Ok(());
        };
        live.viewer.advance(dt);
        let texture = match live.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                live.surface.configure(live.gpu().device(), &live.config);
                live.window.request_redraw();
                return Ok(());
            }
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                live.window.request_redraw();
                return Ok(());
            }
            wgpu::CurrentSurfaceTexture::Validation => {
                return Err(ViewError::Window("the window's surface was refused".into()));
            }
        };
        let window_size = (live.config.width, live.config.height);
        let size = live.viewer.frame_size(window_size)?;
        let camera = live.viewer.camera.camera(size.0, size.1)?;
        let view = texture
            .texture
            .create_view(&wgpu::TextureViewDescriptor::default());
        let mut encoder =
            live.gpu()
                .device()
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("frf view frame"),
                });
        let drawn = live.viewer.shot.draw_at(
            &mut encoder,
            live.viewer.time,
            &camera,
            live.timer.as_ref().map(GpuTimer::begin_pass),
        )?;
        live.present.draw(
            live.gpu(),
            &mut encoder,
            &drawn,
            &view,
            window_size,
            live.viewer.layer,
            live.viewer.exposure,
            live.timer.as_ref().map(GpuTimer::end_pass),
        );
        if let Some(t) = &mut live.timer {
            t.end(&mut encoder);
        }
        // The panel, over the frame.
        let figures = Figures {
            gpu_ms: live.timer.as_ref().and_then(GpuTimer::latest_ms),
            timestamps: live.timer.is_some(),
            frame_ms: median(&self.frame_ms[self.frame_ms.len().saturating_sub(30)..]),
            resident_mb: live.viewer.shot.resident_bytes() as f64 / 1e6,
            size,
            adapter: live.adapter.clone(),
        };
        let message = &mut self.message;
        let (actions, extra, repaint_now) = live.draw_panel(
            &mut encoder,
            &view,
            window_size,
            show_panel.then_some(&figures),
            message,
        );
        let (device, queue) = live.device_and_queue();
        queue.submit(extra.into_iter().chain([encoder.finish()]));
        queue.present(texture);
        if let Some(t) = &mut live.timer {
            t.submitted();
        }
        let _ = device.poll(wgpu::PollType::Poll);
        if let Some(ms) = live.timer.as_ref().and_then(GpuTimer::latest_ms)
            && self.frames > 0
        {
            self.gpu_ms.push(ms);
        }
        self.frames += 1;
        if actions.screenshot {
            self.screenshot()?;
        }
        if actions.quit {
            self.ended = Some(Ended::Quit);
            event_loop.exit();
            return Ok(());
        }
        if self.run_script_after()? {
            self.ended = Some(Ended::Quit);
            event_loop.exit();
            return Ok(());
        }
        if let Some(live) = &self.live
            && (live.viewer.playing || self.script.is_some() || !self.held.is_empty())
        {
            live.window.request_redraw();
        }
        if let Some(live) = &self.live
            && repaint_now
        {
            live.window.request_redraw();
        }
        Ok(())
    }

    /// Writes the frame shown to `frf-view-NNN.png` in the working directory.
    fn screenshot(&mut self) -> Result<(), ViewError> {
        let Some(live) = &mut self.live else {
            return Ok(());
        };
        let path = loop {
            let p = std::path::PathBuf::from(format!("frf-view-{:03}.png", self.screenshot_count));
            self.screenshot_count += 1;
            if !p.exists() {
                break p;
            }
        };
        live.viewer
            .screenshot(&path, (live.config.width, live.config.height))?;
        self.message = Some(format!("wrote {}", path.display()));
        self.screenshots.push(path);
        Ok(())
    }

    /// Flies and looks with the keys held, for `dt` seconds.
    fn move_with_held_keys(&mut self, dt: f32) {
        let Some(live) = &mut self.live else {
            return;
        };
        let c = &mut live.viewer.camera;
        let step = FLY_SPEED * c.distance.max(0.5) * dt;
        let turn = LOOK_SPEED * dt;
        for key in &self.held {
            match key {
                KeyCode::KeyW => c.fly(step, 0.0, 0.0),
                KeyCode::KeyS => c.fly(-step, 0.0, 0.0),
                KeyCode::KeyA => c.fly(0.0, -step, 0.0),
                KeyCode::KeyD => c.fly(0.0, step, 0.0),
                KeyCode::KeyE => c.fly(0.0, 0.0, step),
                KeyCode::KeyQ => c.fly(0.0, 0.0, -step),
                KeyCode::ArrowLeft => c.look(-turn, 0.0),
                KeyCode::ArrowRight => c.look(turn, 0.0),
                KeyCode::ArrowUp => c.look(0.0, turn),
                KeyCode::ArrowDown => c.look(0.0, -turn),
                _ => {}
            }
        }
    }

    /// A key pressed once (not held): the viewer's shortcuts.
    fn key_pressed(
        &mut self,
        event_loop: &ActiveEventLoop,
        code: KeyCode,
    ) -> Result<(), ViewError> {
        let Some(live) = &mut self.live else {
            return Ok(());
        };
        let v = &mut live.viewer;
        match code {
            KeyCode::Space => v.playing = !v.playing,
            KeyCode::Comma => v.step(-1),
            KeyCode::Period => v.step(1),
            KeyCode::KeyR | KeyCode::Home => v.reset()?,
            KeyCode::KeyG => v.snap()?,
            KeyCode::KeyK => {
                v.key();
                self.message = Some(format!("{} keys recorded", v.recording.keys().len()));
            }
            KeyCode::Digit1
            | KeyCode::Digit2
            | KeyCode::Digit3
            | KeyCode::Digit4
            | KeyCode::Digit5 => {
                let i = match code {
                    KeyCode::Digit1 => 0,
                    KeyCode::Digit2 => 1,
                    KeyCode::Digit3 => 2,
                    KeyCode::Digit4 => 3,
                    _ => 4,
                };
                v.layer = ShownLayer::ALL[i];
            }
            KeyCode::KeyV => {
                let all = Variant::ALL;
                let now = v.shot.scene().variant;
                let i = all.iter().position(|x| *x == now).unwrap_or(0);
                v.set_variant(all[(i + 1) % all.len()])?;
            }
            KeyCode::KeyB => {
                let offered = v.backdrops();
                let i = offered.iter().position(|b| *b == v.backdrop()).unwrap_or(0);
                v.set_backdrop(offered[(i + 1) % offered.len()])?;
            }
            KeyCode::KeyH => v.set_shadow(!v.shadow())?,
            KeyCode::KeyL if !v.envs.is_empty() => {
                let i = v
                    .env
                    .or(v.env_index())
                    .map_or(0, |i| (i + 1) % v.envs.len());
                v.set_env(i)?;
            }
            KeyCode::BracketLeft => v.set_yaw(v.yaw_deg - 15.0)?,
            KeyCode::BracketRight => v.set_yaw(v.yaw_deg + 15.0)?,
            KeyCode::Minus => v.camera.zoom(1.1),
            KeyCode::Equal => v.camera.zoom(1.0 / 1.1),
            KeyCode::KeyP => self.screenshot()?,
            KeyCode::F1 => self.show_panel = !self.show_panel,
            KeyCode::Escape => {
                self.ended = Some(Ended::Quit);
                event_loop.exit();
            }
            _ => {}
        }
        Ok(())
    }

    /// Mouse moved to `(x, y)`: orbit with the left button, pan with the right or middle
    /// one (or shift and the left).
    fn cursor_moved(&mut self, x: f64, y: f64) {
        let (dx, dy) = ((x - self.cursor.0) as f32, (y - self.cursor.1) as f32);
        self.cursor = (x, y);
        let (Some((button, _)), Some(live)) = (self.drag, &mut self.live) else {
            return;
        };
        let c = &mut live.viewer.camera;
        let height = live.config.height.max(1) as f32;
        let pan = button != MouseButton::Left || self.modifiers.shift_key();
        if pan {
            c.pan(-dx / height, dy / height);
        } else {
            c.orbit(-dx * ORBIT_PER_PX, dy * ORBIT_PER_PX);
        }
        live.window.request_redraw();
    }
}

/// The median of `v` (`None` when empty).
pub(crate) fn median(v: &[f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    Some(s[s.len() / 2])
}

impl ApplicationHandler for App<'_> {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        // The window may be closed while it is still being set up (opening the field and
        // the GPU takes seconds): caught as in `window_event`.
        let opened = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            quietly(|| self.open(event_loop))
        }));
        match opened {
            Ok(Ok(())) => {}
            Ok(Err(e)) => return self.fail(event_loop, e),
            Err(panic) => return self.went_away(event_loop, &panic),
        }
        if let Some(live) = &self.live {
            live.window.request_redraw();
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        // Events queued before the end (a redraw after the window was destroyed) are not
        // handled: the window may be gone.
        if self.ended.is_some() || self.error.is_some() {
            return;
        }
        let handled = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            quietly(|| self.handle(event_loop, event))
        }));
        if let Err(panic) = handled {
            self.went_away(event_loop, &panic);
        }
    }
}

impl App<'_> {
    /// Ends on a panic of the window system's library caught while the window was used
    /// (see [`quietly`]).
    fn went_away(&mut self, event_loop: &ActiveEventLoop, panic: &Box<dyn std::any::Any + Send>) {
        self.fail(
            event_loop,
            ViewError::Window(format!(
                "the window went away while in use ({})",
                panic_message(panic)
            )),
        );
    }
}

thread_local! {
    /// Whether a panic on this thread is caught and said as an error (see [`quietly`]).
    static QUIET: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Runs `f` with panics not printed: the window system's library panics when a window
/// another client destroyed is used before its destruction is known (winit's X11
/// backend unwraps a failed `GetGeometry`); the caller catches it and says it as an
/// error instead.
fn quietly<T>(f: impl FnOnce() -> T) -> T {
    static HOOK: std::sync::Once = std::sync::Once::new();
    HOOK.call_once(|| {
        let default = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !QUIET.with(std::cell::Cell::get) {
                default(info);
            }
        }));
    });
    QUIET.with(|q| q.set(true));
    struct Loud;
    impl Drop for Loud {
        fn drop(&mut self) {
            QUIET.with(|q| q.set(false));
        }
    }
    let _loud = Loud;
    f()
}

/// The message of a caught panic.
fn panic_message(panic: &Box<dyn std::any::Any + Send>) -> String {
    panic
        .downcast_ref::<String>()
        .cloned()
        .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
        .unwrap_or_else(|| "no message".into())
}

impl App<'_> {
    /// Handles a window event (see [`ApplicationHandler::window_event`]).
    fn handle(&mut self, event_loop: &ActiveEventLoop, event: WindowEvent) {
        let Some(live) = &mut self.live else {
            return;
        };
        let response = live.egui.on_window_event(&live.window, &event);
        if response.repaint {
            live.window.request_redraw();
        }
        let result = match event {
            WindowEvent::CloseRequested | WindowEvent::Destroyed => {
                self.ended = Some(Ended::WindowClosed);
                event_loop.exit();
                Ok(())
            }
            WindowEvent::Resized(size) => {
                if size.width > 0 && size.height > 0 {
                    live.config.width = size.width;
                    live.config.height = size.height;
                    live.surface.configure(live.gpu().device(), &live.config);
                    live.window.request_redraw();
                }
                Ok(())
            }
            WindowEvent::RedrawRequested => self.frame(event_loop),
            WindowEvent::ModifiersChanged(m) => {
                self.modifiers = m.state();
                Ok(())
            }
            _ if response.consumed => Ok(()),
            WindowEvent::KeyboardInput { event, .. } => {
                let PhysicalKey::Code(code) = event.physical_key else {
                    return;
                };
                live.window.request_redraw();
                match event.state {
                    ElementState::Pressed => {
                        self.held.insert(code);
                        if event.repeat {
                            Ok(())
                        } else {
                            self.key_pressed(event_loop, code)
                        }
                    }
                    ElementState::Released => {
                        self.held.remove(&code);
                        Ok(())
                    }
                }
            }
            WindowEvent::MouseInput { state, button, .. } => {
                self.drag = match state {
                    ElementState::Pressed => Some((button, self.cursor)),
                    ElementState::Released => None,
                };
                Ok(())
            }
            WindowEvent::CursorMoved { position, .. } => {
                self.cursor_moved(position.x, position.y);
                Ok(())
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                let c = &mut live.viewer.camera;
                if self.modifiers.control_key() {
                    c.zoom(0.95f32.powf(lines));
                } else {
                    c.dolly(0.9f32.powf(lines));
                }
                live.window.request_redraw();
                Ok(())
            }
            _ => Ok(()),
        };
        if let Err(e) = result {
            // A script's failure, or a frame that cannot be drawn, ends the viewer; a
            // refused change asked for by a person is said in the panel.
            let fatal = self.script.is_some()
                || matches!(
                    e,
                    ViewError::Render(_)
                        | ViewError::Scene(_)
                        | ViewError::Window(_)
                        | ViewError::ScriptFailed { .. }
                );
            if fatal {
                self.fail(event_loop, e);
            } else {
                self.message = Some(e.to_string());
                if let Some(live) = &self.live {
                    live.window.request_redraw();
                }
            }
        }
    }
}
