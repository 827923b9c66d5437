//! Which adapter renders, chosen deliberately: every adapter of the backends wgpu was
//! asked for (`WGPU_BACKEND`, else all) is checked against what the renderer's passes
//! need, and the best one that has all of it is taken: a native backend (Vulkan, Metal,
//! DX12) before GL, a discrete GPU before an integrated one, a virtual one, a CPU
//! (lavapipe) and anything else. A name (`frf --adapter NAME`, or `FRF_ADAPTER`) picks
//! the adapter whose name or backend contains it.
//!
//! What the passes need: `rgba32float` targets drawn into (the composite and the bench's
//! fragment passes) and written as storage (the frame, relighting and shadow passes), nine
//! storage buffers in one compute stage (the frame pass's counters, the shared pages of
//! pre-lit views and of flows, and six of the pose's tables) and a uniform binding of
//! 256 renders' frame records (64 KiB). The GL backend of Mesa, for one, cannot draw into `rgba32float`:
//! on a machine that has both, the default adapter used to be GL and every render failed
//! ("Format Rgba32Float is not renderable"); a machine with GL alone is told so, and to
//! render with `--cpu`.
//!
//! A process opens one wgpu instance and enumerates its adapters once ([`shared`]); every
//! [`super::Gpu`] it opens after that is a device of one of those adapters. Opening an
//! instance per device, as each GPU test did, brings every backend up and down again
//! (the GL backend's EGL display is initialised and terminated with each instance): on a
//! real GPU, tests opening devices on four threads at once then waited forever with the
//! GPU idle, where each alone passed. One instance, made once, takes that away.

use std::sync::OnceLock;

use serde::Serialize;

use crate::error::{RenderError, Result};

/// The environment variable that names the adapter to take.
pub const ADAPTER_ENV: &str = "FRF_ADAPTER";

/// Storage buffers the frame pass binds in its compute stage.
const STORAGE_BUFFERS: u32 = 9;
/// Bytes of the frame records one dispatch of the frame pass binds.
const FRAME_RECORDS_BYTES: u64 = size_of::<super::rebin::FrameRecords>() as u64;

/// The adapter named on the command line, which wins over [`ADAPTER_ENV`].
static PREFERRED: OnceLock<String> = OnceLock::new();

/// Names the adapter every GPU of this process opens ([`choose`]); the first call wins.
pub fn prefer(name: &str) {
    let _ = PREFERRED.set(name.to_string());
}

/// The adapter named on the command line, if one was ([`prefer`]): for the processes
/// this one starts.
pub fn preferred() -> Option<&'static str> {
    PREFERRED.get().map(String::as_str)
}

/// One adapter found, and what the renderer's passes need that it lacks.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Candidate {
    /// `name (backend, device type)`.
    pub adapter: String,
    /// What it lacks; empty when it can run every pass.
    pub lacks: Vec<String>,
}

/// The adapter taken, why, and every one that was considered.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct AdapterReport {
    /// The adapter's name.
    pub name: String,
    /// Its backend (`Vulkan`, `Gl`, ...).
    pub backend: String,
    /// Its kind (`DiscreteGpu`, `Cpu`, ...).
    pub device_type: String,
    /// Its driver and version, as it reports them.
    pub driver: String,
    /// Why it was taken.
    pub why: String,
    /// Every adapter found, in the order of preference.
    pub candidates: Vec<Candidate>,
}

fn describe(info: &wgpu::AdapterInfo) -> String {
    format!("{} ({:?}, {:?})", info.name, info.backend, info.device_type)
}

/// What the renderer's passes need that `adapter` lacks.
pub fn lacks(adapter: &wgpu::Adapter) -> Vec<String> {
    use wgpu::TextureUsages as U;
    let mut out = Vec::new();
    let needs = [
        (
            wgpu::TextureFormat::Rgba32Float,
            U::RENDER_ATTACHMENT,
            "rgba32float render targets",
        ),
        (
            wgpu::TextureFormat::Rgba32Float,
            U::STORAGE_BINDING,
            "rgba32float storage textures",
        ),
    ];
    for (format, usage, what) in needs {
        if !adapter
            .get_texture_format_features(format)
            .allowed_usages
            .contains(usage)
        {
            out.push(what.to_string());
        }
    }
    let limits = adapter.limits();
    if limits.max_storage_buffers_per_shader_stage < STORAGE_BUFFERS {
        out.push(format!(
            "{STORAGE_BUFFERS} storage buffers per shader stage (it has {})",
            limits.max_storage_buffers_per_shader_stage
        ));
    }
    if limits.max_uniform_buffer_binding_size < FRAME_RECORDS_BYTES {
        out.push(format!(
            "a uniform binding of {FRAME_RECORDS_BYTES} bytes (it has {})",
            limits.max_uniform_buffer_binding_size
        ));
    }
    if limits.max_storage_textures_per_shader_stage < 1 {
        out.push("a storage texture per shader stage".into());
    }
    out
}

/// Rank of an adapter's backend and kind: lower is preferred.
fn rank(info: &wgpu::AdapterInfo) -> (u8, u8) {
    let backend = match info.backend {
        wgpu::Backend::Vulkan | wgpu::Backend::Metal | wgpu::Backend::Dx12 => 0,
        wgpu::Backend::Gl => 1,
        _ => 2,
    };
    let kind = match info.device_type {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Cpu => 3,
        wgpu::DeviceType::Other => 4,
    };
    (backend, kind)
}

/// The name asked for: [`prefer`]'s, else [`ADAPTER_ENV`]'s (empty is none).
fn wanted() -> Option<String> {
    PREFERRED
        .get()
        .cloned()
        .or_else(|| std::env::var(ADAPTER_ENV).ok())
        .filter(|s| !s.trim().is_empty())
}

/// [`shared`]'s instance and adapters, once made.
static SHARED: OnceLock<(wgpu::Instance, Vec<wgpu::Adapter>)> = OnceLock::new();

/// The process's wgpu instance (backends from `WGPU_BACKEND`, else all) and its
/// adapters, made on the first call and shared by every later one (see the module text).
pub fn shared() -> &'static (wgpu::Instance, Vec<wgpu::Adapter>) {
    SHARED.get_or_init(|| {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()));
        (instance, adapters)
    })
}

/// Every adapter of `instance` with what it lacks, preferred first.
pub fn candidates(instance: &wgpu::Instance) -> Vec<(wgpu::Adapter, Candidate)> {
    candidates_for(instance, None)
}

/// Every adapter of `instance` with what it lacks (with `surface`, presenting to it too),
/// preferred first; the process's [`shared`] instance answers from the adapters it found.
fn candidates_for(
    instance: &wgpu::Instance,
    surface: Option<&wgpu::Surface>,
) -> Vec<(wgpu::Adapter, Candidate)> {
    let adapters = match SHARED.get() {
        Some((own, found)) if own == instance => found.clone(),
        _ => pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all())),
    };
    let mut all: Vec<(wgpu::Adapter, Candidate)> = adapters
        .into_iter()
        .map(|a| {
            let mut lacks = lacks(&a);
            if surface.is_some_and(|s| !a.is_surface_supported(s)) {
                lacks.push("presenting to the window".into());
            }
            let c = Candidate {
                adapter: describe(&a.get_info()),
                lacks,
            };
            (a, c)
        })
        .collect();
    all.sort_by_key(|(a, c)| (!c.lacks.is_empty(), rank(&a.get_info())));
    all
}

/// The adapter to render with (see the module docs), and the report of the choice.
pub fn choose(instance: &wgpu::Instance) -> Result<(wgpu::Adapter, AdapterReport)> {
    choose_for(instance, None)
}

/// The adapter to render with that can also present to `surface` (a window's), when one
/// is given, and the report of the choice.
pub fn choose_for(
    instance: &wgpu::Instance,
    surface: Option<&wgpu::Surface>,
) -> Result<(wgpu::Adapter, AdapterReport)> {
    let all = candidates_for(instance, surface);
    let listed: Vec<Candidate> = all.iter().map(|(_, c)| c.clone()).collect();
    let summary = || {
        listed
            .iter()
            .map(|c| {
                if c.lacks.is_empty() {
                    c.adapter.clone()
                } else {
                    format!("{} lacks {}", c.adapter, c.lacks.join(", "))
                }
            })
            .collect::<Vec<_>>()
            .join("; ")
    };
    if all.is_empty() {
        return Err(RenderError::Gpu(
            "no GPU adapter; on Debian `apt-get install mesa-vulkan-drivers libvulkan1` provides \
             a software one (lavapipe), or render with --cpu"
                .into(),
        ));
    }
    let name = wanted();
    let (adapter, why) = match &name {
        Some(n) => {
            let needle = n.to_lowercase();
            let Some((adapter, c)) = all.into_iter().find(|(a, _)| {
                let info = a.get_info();
                info.name.to_lowercase().contains(&needle)
                    || format!("{:?}", info.backend)
                        .to_lowercase()
                        .contains(&needle)
            }) else {
                let allowed = format!(
                    "a GPU adapter's name (or {ADAPTER_ENV}); found: {}",
                    summary()
                );
                return Err(frf_core::BadArgument::new("--adapter", n, allowed).into());
            };
            if !c.lacks.is_empty() {
                return Err(RenderError::Gpu(format!(
                    "the adapter `{n}` asked for, {}, cannot run the renderer's passes: it lacks \
                     {}; pick another (found: {}) or render with --cpu",
                    c.adapter,
                    c.lacks.join(", "),
                    summary()
                )));
            }
            (adapter, format!("named `{n}`"))
        }
        None => {
            let Some((adapter, _)) = all.into_iter().find(|(_, c)| c.lacks.is_empty()) else {
                return Err(RenderError::Gpu(format!(
                    "no GPU adapter can run the renderer's passes ({}); render with --cpu, or \
                     install Mesa's Vulkan driver (`apt-get install mesa-vulkan-drivers \
                     libvulkan1`)",
                    summary()
                )));
            };
            let able = listed.iter().filter(|c| c.lacks.is_empty()).count();
            let why = if listed.len() == 1 {
                "the only adapter; it can run every pass".to_string()
            } else {
                format!(
                    "{able} of {} adapters can run every pass; preferred: native backends \
                     before GL, then discrete, integrated, virtual, CPU",
                    listed.len()
                )
            };
            (adapter, why)
        }
    };
    let info = adapter.get_info();
    let report = AdapterReport {
        name: info.name.clone(),
        backend: format!("{:?}", info.backend),
        device_type: format!("{:?}", info.device_type),
        driver: format!("{} {}", info.driver, info.driver_info)
            .trim()
            .to_string(),
        why,
        candidates: listed,
    };
    Ok((adapter, report))
}

/// Every adapter found (preferred first, with what it lacks) and the choice
/// [`choose`] makes among them, for a report (`frf info --gpu`).
pub fn survey() -> (Vec<Candidate>, Result<AdapterReport>) {
    let instance = &shared().0;
    let found = candidates(instance).into_iter().map(|(_, c)| c).collect();
    (found, choose(instance).map(|(_, report)| report))
}

/// Keeps Mesa's Vulkan device-selection layer from probing for a display server: loaded
/// into every Vulkan process, it connects to Wayland to find the desktop's GPU, and
/// outside a desktop session (a batch job, ssh) libwayland prints `error: XDG_RUNTIME_DIR
/// is invalid or not set in the environment.` once per adapter enumeration. Its ordering
/// of the GPUs is not used here (this module ranks them itself), so a program that opens
/// no window turns it off at start-up, before any thread, as its own variable does; a
/// user who set either of its variables keeps the choice.
#[allow(unsafe_code)]
pub fn keep_the_display_probe_quiet() {
    if std::env::var_os("NODEVICE_SELECT").is_none()
        && std::env::var_os("MESA_VK_DEVICE_SELECT").is_none()
    {
        // SAFETY: at start-up, before any thread is spawned: no other thread reads the
        // environment while it changes.
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    }
}
