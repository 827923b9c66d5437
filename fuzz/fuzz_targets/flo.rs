//! A `.flo` file of arbitrary bytes: decoding must return a flow or an error, never
//! panic or allocate more than its header's size allows.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = frf_core::flo::decode_flo(std::path::Path::new("fuzz.flo"), data);
});
