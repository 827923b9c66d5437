//! What every evaluation of a field reads first: the field, its pose relit by the
//! environment, the environment (the truth is relit by it too) and the capture's stage.

use frf_core::env::EnvMap;
use frf_reflectance::FieldFile;
use frf_render::resident::PoseSource;
use frf_stage::Stage;

use super::args::EvalArgs;
use crate::CliResult;

/// The field, pose, environment and stage of `frf eval`.
pub struct EvalInput {
    /// The field.
    pub field: FieldFile,
    /// The pose evaluated.
    pub pose: u32,
    /// Its views relit by the environment.
    pub source: PoseSource,
    /// The environment.
    pub env: EnvMap,
    /// The capture's stage (the truth).
    pub stage: Stage,
}

/// Reads what the arguments name, refusing what cannot be judged.
pub fn load(args: &EvalArgs) -> CliResult<EvalInput> {
    let field = FieldFile::open(&args.field)?;
    let h = field.header();
    let pose = field.pose_or_first(args.pose)?;
    let (lighting, env) = args.lighting.lighting(h.conditions.len())?;
    let env = env.ok_or("frf eval needs an environment (the truth is relit by it)")?;
    frf_core::argument::within("--lights", args.lights, 1, 65536, "")?;
    let stage = frf_stage::open_stage(&args.capture)?;
    if !stage.config().poses.contains(&pose) {
        return Err(frf_reflectance::ReflectanceError::NoSuchPose {
            file: Some(args.capture.clone()),
            within: "capture",
            pose,
            held: frf_reflectance::field::listed(&stage.config().poses),
        }
        .into());
    }
    let source = PoseSource::load(&field, pose, &lighting)?;
    Ok(EvalInput {
        field,
        pose,
        source,
        env,
        stage,
    })
}
