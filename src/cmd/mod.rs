//! One module per subcommand, plus shared progress reporting and argument parsing.

pub mod eval;
pub mod flow;
pub mod info;
pub mod ingest;
pub mod progress;
pub mod render;
pub mod stage;
pub mod stage_field;

use crate::CliResult;

/// Parses `--poses`: a list `0,1` or a half-open range `0..4`.
pub fn parse_poses(s: &str) -> CliResult<Vec<u32>> {
    let bad = || format!("--poses {s:?}: expected e.g. 0,1 or 0..4");
    if let Some((a, b)) = s.split_once("..") {
        let (a, b): (u32, u32) = (
            a.trim().parse().map_err(|_| bad())?,
            b.trim().parse().map_err(|_| bad())?,
        );
        if a >= b {
            return Err(bad().into());
        }
        return Ok((a..b).collect());
    }
    s.split(',')
        .map(|p| p.trim().parse().map_err(|_| bad().into()))
        .collect()
}
