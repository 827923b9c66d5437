//! Huffman tables and flow maps of arbitrary bytes: decoding must return errors, never
//! panic; a table that parses must decode any stream without panicking.
#![no_main]

use frf_reflectance::flowcodec::{self, huffman::HuffmanTable, quant::LogQuantizer};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(q) = LogQuantizer::new(0.3, 20.0) {
        let _ = flowcodec::decode(data, &q);
    }
    if data.len() >= 130
        && let Ok(table) = HuffmanTable::from_bytes(&data[..128])
    {
        let count = u16::from_le_bytes([data[128], data[129]]) as usize;
        let _ = table.decode(&data[130..], count);
    }
});
