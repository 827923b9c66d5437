//! A command's file output claimed before its work ([`frf_core::claim`]), saying which
//! temporary files of earlier interrupted runs it removed.

use std::path::Path;

use frf_core::claim::{OutputClaim, claim_output};

use crate::CliResult;

/// Claims `out`, and also clears the temporaries in `private_dirs` (directories only this
/// output's writer uses); hold the claim until the output is written.
pub fn claim(out: &Path, private_dirs: &[&Path]) -> CliResult<OutputClaim> {
    let mut claim = claim_output(out)?;
    for dir in private_dirs {
        claim.clear_temporaries_in(dir);
    }
    if let Some(note) = claim.removed_note() {
        eprintln!("{note}");
    }
    Ok(claim)
}
