//! `frf`: the command-line front end of the flowed-reflectance-field pipeline. It only
//! parses arguments, shows progress and wires the crates; every computation lives in the
//! library crates (`frf-stage`, `frf-flow`, `frf-reflectance`, `frf-ingest`, `frf-render`).

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use frf_core::Fault;

mod cmd;
mod context;

/// Errors of the binary: any library error, printed with its chain of causes.
pub type CliResult<T = ()> = Result<T, Box<dyn std::error::Error + Send + Sync>>;

#[derive(Parser)]
#[command(
    name = "frf",
    version,
    about = "Flowed reflectance fields: capture, store, relight and render walking people"
)]
struct Cli {
    /// The GPU adapter to render with: the one whose name or backend contains NAME (also
    /// `FRF_ADAPTER`); by default the best one that can run every pass (`frf info --gpu`
    /// lists them).
    #[arg(long, global = true, value_name = "NAME")]
    adapter: Option<String>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a synthetic capture with the virtual light stage, or its ground truth.
    Stage(Box<cmd::stage::StageArgs>),
    /// Show what a field file holds and how well it is compressed, or (`--gpu`) the GPU
    /// adapters and which one renders.
    Info(cmd::info::InfoArgs),
    /// Write a pose's visual hull as a mesh (PLY).
    Hull(cmd::hull::HullArgs),
    /// Turn a capture into a flowed reflectance field (mattes, registration, flow).
    Ingest(cmd::ingest::IngestArgs),
    /// Join fields holding disjoint poses (parts ingested apart) into one field.
    Merge(cmd::merge::MergeArgs),
    /// Turn a calibrated ring of photographs (Middlebury multi-view) into a field.
    IngestRing(cmd::ingest::RingArgs),
    /// Render a scene (SCENE.toml), or frames of a field along a camera path: relit,
    /// shadowed, composited.
    Render(Box<cmd::render::RenderArgs>),
    /// Score renders between the grid's views against the virtual stage's truth.
    Eval(Box<cmd::eval::EvalArgs>),
    /// Score views held out of a ring of photographs, rendered from their neighbours.
    EvalRing(cmd::eval::RingEvalArgs),
    /// Turn a calibrated one-light-at-a-time set of photographs into a one-view field
    /// whose basis is its lights.
    IngestOlat(cmd::olat::IngestOlatArgs),
    /// Score relighting on one-light-at-a-time photographs: lights held out of a
    /// calibrated set (or of a field of it), predicted from the others.
    EvalOlat(cmd::olat::EvalOlatArgs),
    /// Error against run time of every stage's settings on a stage capture: JSON, plots,
    /// and one page.
    Report(cmd::report::ReportArgs),
    /// Look at a field or a scene in a window: move the camera, play the walk, turn the
    /// light; record a camera move as a scene file.
    View(Box<cmd::view::ViewArgs>),
    /// The walker as binary glTF (`.glb`) for engines and the web player: hull meshes
    /// that walk in any viewer, and per view its SH transfer, normals, albedo and flows.
    Export(cmd::export::ExportArgs),
    /// An environment's light as nine RGB spherical-harmonic coefficients (L2, the
    /// engines' light probes) in a JSON file frf and players relight by.
    EnvSh(cmd::env_sh::EnvShArgs),
    /// Benchmarks: `frf bench interp` times the GPU interpolation passes.
    Bench(cmd::bench::BenchArgs),
    /// Optical flow from image A to image B, written as a Middlebury .flo file.
    Flow(cmd::flow::FlowArgs),
    /// Error and time of the flow estimator on Middlebury or Sintel pairs with ground truth.
    FlowBench(cmd::flow::FlowBenchArgs),
}

/// Lets a closed pipe end the program quietly, as it ends `cat` or `grep`: Rust ignores
/// SIGPIPE, so `frf eval ... | head` would otherwise panic in `println!` once `head` exits.
#[allow(unsafe_code)]
fn die_quietly_on_a_closed_pipe() {
    // SAFETY: restoring a signal's default disposition at start-up, before any thread is
    // spawned, touches no memory of ours.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// An interrupt (Ctrl-C, SIGTERM) ends the program as before (status 130), after removing
/// the lock files and temporaries of the outputs it was writing
/// ([`frf_core::claim::abandon_live_claims`]); whole files already written stay, and a
/// rerun resumes from them.
fn clean_up_on_interrupt() {
    let _ = ctrlc::set_handler(|| {
        frf_core::claim::abandon_live_claims();
        std::process::exit(130);
    });
}

fn main() -> ExitCode {
    die_quietly_on_a_closed_pipe();
    clean_up_on_interrupt();
    let cli = Cli::parse();
    if !matches!(cli.command, Command::View(_)) {
        frf_render::gpu::adapter::keep_the_display_probe_quiet();
    }
    if let Some(name) = &cli.adapter {
        frf_render::gpu::adapter::prefer(name);
    }
    let result = match cli.command {
        Command::Stage(args) => cmd::stage::run(*args),
        Command::Info(args) => cmd::info::run(args),
        Command::Hull(args) => cmd::hull::run(args),
        Command::Ingest(args) => cmd::ingest::run(args),
        Command::IngestRing(args) => cmd::ingest::run_ring(args),
        Command::Merge(args) => cmd::merge::run(args),
        Command::Render(args) => cmd::render::run(*args),
        Command::Eval(args) => cmd::eval::run(*args),
        Command::EvalRing(args) => cmd::eval::ring::run(args),
        Command::IngestOlat(args) => cmd::olat::run_ingest(args),
        Command::EvalOlat(args) => cmd::olat::run(args),
        Command::Report(args) => cmd::report::run(args),
        Command::View(args) => cmd::view::run(*args),
        Command::Export(args) => cmd::export::run(args),
        Command::EnvSh(args) => cmd::env_sh::run(args),
        Command::Bench(args) => cmd::bench::run_bench(args),
        Command::Flow(args) => cmd::flow::run(args),
        Command::FlowBench(args) => cmd::flow::run_bench(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            let mut source = e.source();
            while let Some(s) = source {
                eprintln!("  caused by: {s}");
                source = s.source();
            }
            ExitCode::from(fault_of(e.as_ref()).exit_code())
        }
    }
}

/// Who is at fault for a failed command: the libraries' errors say; what the command line
/// itself refuses is a usage error; an error of the operating system is I/O.
fn fault_of(e: &(dyn std::error::Error + 'static)) -> Fault {
    if let Some(c) = e.downcast_ref::<context::Context>() {
        return fault_of(c.inner());
    }
    macro_rules! by_type {
        ($($t:ty),*) => {
            $(if let Some(e) = e.downcast_ref::<$t>() {
                return e.fault();
            })*
        };
    }
    by_type!(
        frf_core::CoreError,
        frf_flow::FlowError,
        frf_reflectance::ReflectanceError,
        frf_ingest::IngestError,
        frf_render::RenderError,
        frf_scene::SceneError,
        frf_stage::StageError,
        frf_eval::EvalError,
        frf_view::ViewError,
        frf_export::ExportError
    );
    if e.downcast_ref::<std::io::Error>().is_some() {
        return Fault::Io;
    }
    Fault::Usage
}
