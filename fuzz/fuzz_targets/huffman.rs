//! Huffman tables and flow maps: decoding must return errors, never panic.
//!
//! Three ways in: the input as a flow-map chunk (seeded with a valid map in
//! `seeds/huffman`); its first 128 bytes as a serialized table; and, so that the decoder
//! sees valid tables whatever the input, a table built from symbol counts taken from the
//! input, a stream encoded with it, and that stream damaged at positions the input picks.
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
    // Built: symbols are the input's bytes; damage is every 16th byte's XOR at its index.
    let mut counts = [0u64; 256];
    for &b in data {
        counts[b as usize] += 1;
    }
    let table = HuffmanTable::from_counts(&counts);
    let back = HuffmanTable::from_bytes(&table.to_bytes()).expect("a built table parses");
    let Ok(mut bits) = table.encode(data) else {
        return;
    };
    assert_eq!(back.decode(&bits, data.len()).ok().as_deref(), Some(data));
    for pair in data.chunks_exact(16) {
        if !bits.is_empty() {
            let at = pair[0] as usize * 256 + pair[1] as usize;
            let n = bits.len();
            bits[at % n] ^= pair[2];
        }
    }
    bits.truncate(bits.len().saturating_sub(data.first().map_or(0, |b| (b % 4) as usize)));
    if let Ok(out) = back.decode(&bits, data.len()) {
        assert_eq!(out.len(), data.len());
    }
});
