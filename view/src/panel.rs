//! The panel (egui): a line of figures (GPU time per frame, frames per second, resident
//! memory, the poses and the camera) and every control of the viewer, each a
//! [`Viewer`] change like its key's.

use frf_render::gpu::present::ShownLayer;
use frf_render::morph::Variant;

use crate::viewer::Viewer;

/// The figures of the frame drawn.
pub struct Figures {
    /// GPU time of the latest frame timed, milliseconds.
    pub gpu_ms: Option<f64>,
    /// Whether the device has timestamp queries.
    pub timestamps: bool,
    /// Median time between recent frames, milliseconds.
    pub frame_ms: Option<f64>,
    /// Resident poses, MB.
    pub resident_mb: f64,
    /// Frame size drawn.
    pub size: (u32, u32),
    /// The adapter.
    pub adapter: String,
}

/// What the panel asks of the window.
#[derive(Debug, Default, Clone, Copy)]
pub struct Actions {
    /// Write a screenshot.
    pub screenshot: bool,
    /// Close the viewer.
    pub quit: bool,
}

/// Shows the panel; a refused change leaves its reason in `message`.
pub fn show(
    ui: &mut egui::Ui,
    v: &mut Viewer,
    f: &Figures,
    message: &mut Option<String>,
) -> Actions {
    let mut actions = Actions::default();
    let ctx = ui.ctx().clone();
    egui::Window::new("frf view")
        .default_width(260.0)
        .resizable(false)
        .show(&ctx, |ui| {
            let result = controls(ui, v, f, &mut actions);
            if let Err(e) = result {
                *message = Some(e.to_string());
            }
            if let Some(m) = message.as_ref() {
                ui.separator();
                ui.label(egui::RichText::new(m).color(egui::Color32::LIGHT_RED));
            }
        });
    actions
}

fn figures_line(ui: &mut egui::Ui, v: &Viewer, f: &Figures) {
    let gpu = match (f.gpu_ms, f.timestamps) {
        (Some(ms), _) => format!("GPU {ms:.2} ms/frame"),
        (None, true) => "GPU … ms/frame".to_string(),
        (None, false) => "GPU time: no timestamp queries".to_string(),
    };
    let fps = f
        .frame_ms
        .filter(|&ms| ms > 0.0)
        .map_or("… fps".to_string(), |ms| format!("{:.1} fps", 1e3 / ms));
    ui.label(format!(
        "{gpu} · {fps} · {:.1} MB resident · {}x{}",
        f.resident_mb, f.size.0, f.size.1
    ));
    let poses = v
        .poses()
        .iter()
        .map(u32::to_string)
        .collect::<Vec<_>>()
        .join(", ");
    let p = v.camera.position();
    ui.label(format!(
        "t {:.3} s · pose {poses} · camera ({:.2}, {:.2}, {:.2}) fov {:.1}°",
        v.time, p.x, p.y, p.z, v.camera.fov_deg
    ));
    ui.label(egui::RichText::new(&f.adapter).small());
}

fn controls(
    ui: &mut egui::Ui,
    v: &mut Viewer,
    f: &Figures,
    actions: &mut Actions,
) -> Result<(), crate::ViewError> {
    figures_line(ui, v, f);
    ui.separator();
    ui.horizontal(|ui| {
        ui.label("camera");
        let mut fov = v.camera.fov_deg;
        if ui
            .add(egui::Slider::new(&mut fov, 5.0..=120.0).text("fov °"))
            .changed()
        {
            v.camera.fov_deg = fov;
        }
    });
    let mut result = Ok(());
    ui.horizontal(|ui| {
        if ui.button("captured view (R)").clicked() {
            result = v.reset();
        }
        if ui.button("snap to grid (G)").clicked() {
            result = v.snap();
        }
    });
    result?;
    ui.separator();
    ui.horizontal(|ui| {
        let label = if v.playing { "pause" } else { "play" };
        if ui.button(format!("{label} (space)")).clicked() {
            v.playing = !v.playing;
        }
        if ui.button("< pose (,)").clicked() {
            v.step(-1);
        }
        if ui.button("pose > (.)").clicked() {
            v.step(1);
        }
    });
    let (a, b) = v.span;
    let mut t = v.time;
    if ui
        .add(egui::Slider::new(&mut t, a..=b).text("time s"))
        .changed()
    {
        v.set_time(t);
    }
    if v.shot.scene().instances.iter().any(|w| w.moves()) {
        ui.checkbox(
            &mut v.show_paths,
            "walkers' paths (the time slider scrubs along them)",
        );
    }
    ui.separator();
    let names: Vec<String> = v.envs.iter().map(|e| e.name()).collect();
    let shown = v.env.or(v.env_index());
    let mut chosen = shown;
    egui::ComboBox::from_label("environment (L)")
        .selected_text(shown.map_or("the scene's".to_string(), |i| names[i].clone()))
        .show_ui(ui, |ui| {
            for (i, n) in names.iter().enumerate() {
                ui.selectable_value(&mut chosen, Some(i), n);
            }
        });
    if chosen != shown
        && let Some(i) = chosen
    {
        v.set_env(i)?;
    }
    let mut yaw = v.yaw_deg;
    if ui
        .add(egui::Slider::new(&mut yaw, -180.0..=180.0).text("yaw ° ([ ])"))
        .changed()
    {
        // Applied while dragged: a new light is one relighting dispatch per pose.
        v.set_yaw(yaw)?;
    }
    let mut k = v.intensity;
    if ui
        .add(
            egui::Slider::new(&mut k, 0.0..=8.0)
                .logarithmic(true)
                .text("intensity"),
        )
        .changed()
    {
        v.set_intensity(k)?;
    }
    ui.separator();
    let now = v.shot.scene().variant;
    let mut variant = now;
    egui::ComboBox::from_label("interpolation (V)")
        .selected_text(variant.name())
        .show_ui(ui, |ui| {
            for x in Variant::ALL {
                ui.selectable_value(&mut variant, x, x.name());
            }
        });
    if variant != now {
        v.set_variant(variant)?;
    }
    let backdrop = v.backdrop();
    let mut chosen = backdrop;
    ui.horizontal(|ui| {
        ui.label("backdrop (B)");
        for b in v.backdrops() {
            ui.radio_value(&mut chosen, b, b.name());
        }
    });
    if chosen != backdrop {
        v.set_backdrop(chosen)?;
    }
    let mut shadow = v.shadow();
    if ui.checkbox(&mut shadow, "shadow (H)").changed() {
        v.set_shadow(shadow)?;
    }
    ui.horizontal(|ui| {
        ui.label("show (1–5)");
        for l in ShownLayer::ALL {
            ui.radio_value(&mut v.layer, l, l.name());
        }
    });
    ui.add(egui::Slider::new(&mut v.exposure, -8.0..=8.0).text("exposure stops"));
    ui.separator();
    ui.horizontal(|ui| {
        if ui.button("key (K)").clicked() {
            v.key();
        }
        ui.label(format!("{} keys recorded", v.recording.keys().len()));
    });
    ui.horizontal(|ui| {
        if ui.button("screenshot (P)").clicked() {
            actions.screenshot = true;
        }
        if ui.button("quit (Esc)").clicked() {
            actions.quit = true;
        }
    });
    Ok(())
}
