//! The wgpu renderer, one module per pass (its layout, pipeline and WGSL together), each
//! the twin of a CPU reference it is tested against:
//!
//! - [`pose`]: a pose made resident;
//! - [`relight`]: its views relit from basis codes kept resident (`shaders/relight.wgsl`;
//!   twin of [`crate::resident::ResidentPose::relight_cpu`]), after [`sun_depth`] made its
//!   suns' maps of the hull (`shaders/sun_depth.wgsl`; twin of
//!   [`frf_reflectance::sun_depth::SunDepth::reach`]);
//! - [`rebin`]: the subject of a frame, re-binned and morphed (`shaders/rebin.wgsl`; twin
//!   of [`crate::cpu::render_cpu`]);
//! - [`shadow`]: the pose's shadow maps relit (`shaders/shadow.wgsl`; twin of
//!   [`crate::shadow::ShadowMaps::relight`]);
//! - [`composite`]: the subject over a shadowed backdrop (`shaders/composite.wgsl`; twin
//!   of [`crate::composite::compose`]);
//! - [`present`]: a composited frame shown in a window, nothing read back
//!   (`shaders/present.wgsl`);
//! - [`light_fit`]: photographs under single lights relit by their per-texel light fit
//!   (`shaders/light_fit.wgsl`; twin of
//!   [`frf_reflectance::light_fit::LightFit::relight`]).
//!
//! [`Gpu::new`] opens an adapter (on machines without a GPU, Mesa's lavapipe; the
//! `WGPU_BACKEND` variable chooses a backend) and builds every pipeline once. Every
//! request runs inside error scopes ([`scope`]). Readback pads rows to
//! `COPY_BYTES_PER_ROW_ALIGNMENT` ([`bind`]).

pub mod adapter;
mod arena;
pub mod bench;
pub mod bind;
pub mod composite;
mod composite_targets;
pub mod formats;
pub mod kept;
pub mod light_fit;
pub mod pass_clock;
pub mod pose;
mod pose_tables;
mod prelit;
pub mod present;
pub mod readback;
pub mod rebin;
pub mod relight;
mod relights;
pub mod scope;
pub mod shadow;
mod spent;
pub mod sun_depth;
pub mod time_morph;
pub mod timing;
pub mod turn_light;
mod uploads;

use crate::error::{RenderError, Result};

pub use pose::GpuPose;

/// The WGSL sources as compiled ([`frf_shaders`]), and a pass made a module on a device.
pub mod shaders {
    pub use frf_shaders::*;

    /// A pass's shader module on `device`.
    pub fn module(device: &wgpu::Device, name: &str, pass: &str) -> wgpu::ShaderModule {
        device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(name),
            source: wgpu::ShaderSource::Wgsl(composed(pass).into()),
        })
    }
}

/// A wgpu error of `operation`, its source kept.
fn wgpu_err<E: std::error::Error + Send + Sync + 'static>(
    operation: &'static str,
) -> impl FnOnce(E) -> RenderError {
    move |e| RenderError::Wgpu {
        operation,
        source: Box::new(e),
    }
}

/// Frame sizes (and walker counts) whose targets a GPU keeps.
const KEPT_TARGETS: usize = 4;

/// Bytes of a page of relit poses' coefficients (a pose's batch of views takes some
/// hundreds of kilobytes at full detail; a larger one opens a page of its own).
const COEFFICIENT_PAGE_BYTES: u64 = 32 << 20;
/// Bytes of a page of what the device looks a light up with (a pose's jobs, conditions
/// and scales: some kilobytes).
const TURN_DATA_PAGE_BYTES: u64 = 4 << 20;

/// An open GPU with the renderer's pipelines.
pub struct Gpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
    adapter: String,
    /// The adapter opened.
    wgpu_adapter: wgpu::Adapter,
    report: adapter::AdapterReport,
    uncaptured: scope::Uncaptured,
    relight: relight::RelightPass,
    /// Work recorded between frames, sent ahead of the next ([`Gpu::submit`]).
    pending: std::sync::Mutex<Option<wgpu::CommandEncoder>>,
    /// Every pose copy relit since the last submission ([`relights`]).
    relights: std::sync::Mutex<relights::Relights>,
    /// Small writes gathered between submissions, sent as one ([`uploads`]).
    uploads: std::sync::Mutex<uploads::Uploads>,
    /// Every relit pose's basis codes, a range each ([`relight`]).
    basis: arena::Arena,
    /// Every relit pose's coefficients, a range each ([`relight`]).
    coefficients: arena::Arena,
    /// Every pose relit on the device: its views' jobs, the field's conditions and the
    /// views' scales, a range each ([`turn_light`]).
    turn_data: arena::Arena,
    /// Every resident pose's pre-lit views, a range each ([`prelit`]).
    prelit: arena::Arena,
    /// The tables of the poses resident, shared by the relit copies of one pose's views
    /// ([`pose_tables`]).
    pose_tables: pose_tables::TablesKept,
    /// The flows' codes of the poses resident, a range each, shared by the copies made
    /// from the same flows ([`prelit`]).
    flow_ranges: prelit::FlowsKept,
    /// Staging sets of frames read back, kept for the next ([`readback`]).
    staging: std::sync::Mutex<Vec<readback::FrameStaging>>,
    /// Time the host has waited on the device ([`Gpu::waited`]).
    waited: spent::Spent,
    /// Time the host has spent in `queue.submit` ([`Gpu::submitted`]).
    submitted: spent::Spent,
    rebin: rebin::RebinPass,
    /// How the frame pass runs.
    stage: rebin::PassKind,
    /// Frame targets kept per size, number of walkers and of pages.
    targets: kept::Kept<((u32, u32), u32, u32), rebin::SubjectTargets>,
    /// The renders of frames between poses kept per size, number of renders (four for
    /// each such walker, [`time_morph`]) and of pages.
    between_targets: kept::Kept<((u32, u32), u32, u32), rebin::SubjectTargets>,
    /// The morph in time of walkers between poses.
    time_morph: time_morph::TimeMorphPass,
    /// Composite targets kept per size, number of walkers and shadow-map size.
    composite_targets:
        kept::Kept<composite_targets::CompositeKey, composite_targets::CompositeTargets>,
    /// Whether passes can be timed on the GPU (`Features::TIMESTAMP_QUERY`).
    timestamps: bool,
    /// Every pass timed, once switched on ([`Gpu::clock_passes`]).
    pass_clock: std::sync::OnceLock<pass_clock::PassClock>,
    shadow: shadow::ShadowPass,
    composite: composite_targets::CompositePass,
    sun_depth: sun_depth::SunDepthPass,
    turn_light: turn_light::TurnLightPass,
}

impl Gpu {
    /// Opens the adapter [`adapter::choose`] takes and builds the pipelines.
    pub fn new() -> Result<Self> {
        Self::on(&adapter::shared().0, None)
    }

    /// Opens the adapter of `instance` [`adapter::choose_for`] takes (one that can present
    /// to `surface`, a window's, when one is given) and builds the pipelines.
    pub fn on(instance: &wgpu::Instance, surface: Option<&wgpu::Surface>) -> Result<Self> {
        let (adapter, report) = adapter::choose_for(instance, surface)?;
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("frf"),
            required_features: adapter.features() & wgpu::Features::TIMESTAMP_QUERY,
            required_limits: limits,
            ..Default::default()
        }))
        .map_err(wgpu_err("opening the device"))?;
        let uncaptured = scope::Uncaptured::default();
        uncaptured.install(&device);
        scope::scoped(&device, &uncaptured, "building the pipelines", || {
            Ok(Self::build(
                adapter,
                device.clone(),
                queue,
                report,
                uncaptured.clone(),
            ))
        })
    }

    /// The pipelines and layouts of the renderer on `device`.
    fn build(
        wgpu_adapter: wgpu::Adapter,
        device: wgpu::Device,
        queue: wgpu::Queue,
        report: adapter::AdapterReport,
        uncaptured: scope::Uncaptured,
    ) -> Self {
        let adapter = format!(
            "{} ({}, {})",
            report.name, report.backend, report.device_type
        );
        Self {
            relight: relight::RelightPass::new(&device),
            pending: std::sync::Mutex::new(None),
            relights: std::sync::Mutex::default(),
            uploads: std::sync::Mutex::default(),
            basis: arena::Arena::new(
                &device,
                "basis codes",
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                relight::BASIS_PAGE_BYTES,
            ),
            coefficients: arena::Arena::new(
                &device,
                "coefficients",
                wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                COEFFICIENT_PAGE_BYTES,
            ),
            turn_data: arena::Arena::new(
                &device,
                "turn data",
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                TURN_DATA_PAGE_BYTES,
            ),
            prelit: arena::Arena::new(
                &device,
                "pre-lit views",
                wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                prelit::PRELIT_PAGE_BYTES,
            ),
            pose_tables: pose_tables::TablesKept::default(),
            flow_ranges: prelit::FlowsKept::default(),
            staging: std::sync::Mutex::new(Vec::new()),
            waited: spent::Spent::default(),
            submitted: spent::Spent::default(),
            rebin: rebin::RebinPass::new(&device, formats::PoseFormats::DEFAULT),
            stage: rebin::PassKind::Compute,
            targets: kept::Kept::new(KEPT_TARGETS),
            between_targets: kept::Kept::new(KEPT_TARGETS),
            time_morph: time_morph::TimeMorphPass::new(&device),
            composite_targets: kept::Kept::new(KEPT_TARGETS),
            timestamps: device.features().contains(wgpu::Features::TIMESTAMP_QUERY),
            pass_clock: std::sync::OnceLock::new(),
            shadow: shadow::ShadowPass::new(&device),
            composite: composite_targets::CompositePass::new(&device),
            sun_depth: sun_depth::SunDepthPass::new(&device),
            turn_light: turn_light::TurnLightPass::new(&device),
            device,
            queue,
            adapter,
            wgpu_adapter,
            report,
            uncaptured,
        }
    }

    /// The device a unit test runs on: `None` (said) where there is none and
    /// `FRF_SKIP_GPU=1` allows it; a missing adapter fails the test otherwise.
    #[cfg(test)]
    pub(crate) fn for_tests() -> Option<Self> {
        match Self::new() {
            Ok(g) => Some(g),
            Err(e) if std::env::var("FRF_SKIP_GPU").is_ok_and(|v| v == "1") => {
                eprintln!("skipped (FRF_SKIP_GPU=1): {e}");
                None
            }
            Err(e) => panic!("no GPU adapter ({e}); install mesa-vulkan-drivers"),
        }
    }

    /// Runs `f` inside error scopes ([`scope::scoped`]).
    pub(crate) fn scoped<T>(
        &self,
        operation: &'static str,
        f: impl FnOnce() -> Result<T>,
    ) -> Result<T> {
        scope::scoped(&self.device, &self.uncaptured, operation, f)
    }

    /// The device, for a caller drawing its own passes beside the renderer's (a
    /// viewer's user interface).
    pub fn device(&self) -> &wgpu::Device {
        &self.device
    }

    /// The adapter the device was opened on (what a window's surface is configured for).
    pub fn wgpu_adapter(&self) -> &wgpu::Adapter {
        &self.wgpu_adapter
    }

    /// The queue of [`Gpu::device`].
    pub fn queue(&self) -> &wgpu::Queue {
        &self.queue
    }

    /// Whether the device can time passes with timestamp queries.
    pub fn has_timestamps(&self) -> bool {
        self.timestamps
    }

    /// The most layers of an array texture the device takes.
    pub fn max_texture_layers(&self) -> u32 {
        self.device.limits().max_texture_array_layers
    }

    /// The largest texture side the device takes, pixels.
    pub fn max_texture_side(&self) -> u32 {
        self.device.limits().max_texture_dimension_2d
    }

    /// The adapter, in words.
    pub fn adapter(&self) -> &str {
        &self.adapter
    }

    /// The adapter, why it was taken, and every one considered.
    pub fn adapter_report(&self) -> &adapter::AdapterReport {
        &self.report
    }

    pub(crate) fn wait(&self) -> Result<()> {
        self.waiting(|| self.device.poll(wgpu::PollType::wait_indefinitely()))
            .map_err(wgpu_err("waiting on the device"))?;
        Ok(())
    }

    /// Runs `f`, a call that may block on the device, counting its time as waiting.
    fn waiting<T>(&self, f: impl FnOnce() -> T) -> T {
        self.waited.run(f)
    }

    /// Submits `buffers` to the queue, counting the time it takes ([`Gpu::submitted`]).
    fn submit_counted(
        &self,
        buffers: impl IntoIterator<Item = wgpu::CommandBuffer>,
    ) -> wgpu::SubmissionIndex {
        self.submitted.run(|| self.queue.submit(buffers))
    }

    /// How long the host has spent submitting so far (inside `queue.submit`): part of
    /// its own work, but where the adapter is software that runs the work submitted on
    /// the calling thread (lavapipe), the device's work too.
    pub fn submitted(&self) -> std::time::Duration {
        self.submitted.wall()
    }

    /// The CPU time of the threads that submitted work or waited on the device, spent
    /// doing so (zero where the system does not say): on a software adapter, the
    /// device's work done on the calling thread ([`spent`]).
    pub fn submitted_and_waited_cpu(&self) -> std::time::Duration {
        self.submitted.cpu() + self.waited.cpu()
    }

    /// How long the host has waited on the device so far (every fence and readback; not
    /// submissions, which are host work): what a frame's wall time less this is the
    /// host's own work.
    pub fn waited(&self) -> std::time::Duration {
        self.waited.wall()
    }

    /// The whole of `buffer` (a `COPY_SRC` buffer the passes write), copied to a readback
    /// buffer labelled `label` and read once the device has written it.
    pub(crate) fn read_back(&self, buffer: &wgpu::Buffer, label: &str) -> Result<Vec<u8>> {
        self.read_back_range(buffer, (0, buffer.size()), label)
    }

    /// `size` bytes of `buffer` from `offset` on (multiples of 4), read back as
    /// [`Gpu::read_back`] reads a whole buffer.
    pub(crate) fn read_back_range(
        &self,
        buffer: &wgpu::Buffer,
        (offset, size): (u64, u64),
        label: &str,
    ) -> Result<Vec<u8>> {
        let readback = bind::readback_buffer(&self.device, label, size);
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
        encoder.copy_buffer_to_buffer(buffer, offset, &readback, 0, size);
        self.submit([encoder.finish()]);
        self.read_buffer(&readback)
    }

    pub(crate) fn read_buffer(&self, buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
        let slice = buffer.slice(..);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.wait()?;
        rx.recv()
            .map_err(wgpu_err("mapping a buffer"))?
            .map_err(wgpu_err("mapping a buffer"))?;
        let bytes = slice
            .get_mapped_range()
            .map_err(wgpu_err("reading a mapped buffer"))?
            .to_vec();
        buffer.unmap();
        Ok(bytes)
    }
}
