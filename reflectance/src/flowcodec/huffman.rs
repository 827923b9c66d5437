//! Canonical Huffman coding of bytes (Huffman 1952; canonical form as in DEFLATE,
//! RFC 1951 section 3.2.2): only the code length of each of the 256 symbols is stored
//! (4 bits each, 128 bytes), codes are limited to [`MAX_CODE_LENGTH`] bits, and bits are
//! written most significant first. Decoding looks up the next [`FAST_BITS`] bits in a
//! table and falls back to the canonical bit-by-bit walk for longer codes.
//!
//! Tables and bit streams come from files, so decoding trusts nothing: an
//! over-subscribed table, a code that no symbol owns, or a stream that ends early is an
//! error, never a panic.

use std::collections::BinaryHeap;

use crate::error::{ReflectanceError, Result};

/// Longest code, bits (fits the 4-bit length field; as in DEFLATE).
pub const MAX_CODE_LENGTH: u8 = 15;
/// Bits resolved by one table lookup when decoding.
const FAST_BITS: u8 = 10;
/// Bytes of a serialized table.
pub const TABLE_BYTES: usize = 128;

fn corrupt(what: impl Into<String>) -> ReflectanceError {
    ReflectanceError::Corrupt(what.into())
}

/// Code lengths (0 = symbol absent) of a canonical Huffman code over bytes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HuffmanTable {
    lengths: [u8; 256],
}

/// Huffman code lengths for `counts` without a length limit.
fn unlimited_lengths(counts: &[u64; 256]) -> [u8; 256] {
    #[derive(PartialEq, Eq, PartialOrd, Ord)]
    struct Node(std::cmp::Reverse<u64>, usize);
    let mut lengths = [0u8; 256];
    let present: Vec<usize> = (0..256).filter(|&s| counts[s] > 0).collect();
    match present.len() {
        0 => return lengths,
        1 => {
            lengths[present[0]] = 1;
            return lengths;
        }
        _ => {}
    }
    // Nodes 0..256 are leaves; internal nodes follow; parent[] links them.
    let mut parent = vec![usize::MAX; 512];
    let mut heap: BinaryHeap<Node> = present
        .iter()
        .map(|&s| Node(std::cmp::Reverse(counts[s]), s))
        .collect();
    let mut next = 256;
    while heap.len() > 1 {
        let (Some(a), Some(b)) = (heap.pop(), heap.pop()) else {
            break;
        };
        parent[a.1] = next;
        parent[b.1] = next;
        heap.push(Node(std::cmp::Reverse(a.0.0 + b.0.0), next));
        next += 1;
    }
    for &s in &present {
        let (mut depth, mut n) = (0u32, s);
        while parent[n] != usize::MAX {
            n = parent[n];
            depth += 1;
        }
        lengths[s] = depth.min(255) as u8;
    }
    lengths
}

impl HuffmanTable {
    /// The optimal code for `counts` among codes no longer than [`MAX_CODE_LENGTH`]: if
    /// the plain Huffman code is too deep, counts are halved (keeping every present
    /// symbol at least 1) until it fits, which flattens the deepest branches first.
    pub fn from_counts(counts: &[u64; 256]) -> Self {
        let mut c = *counts;
        loop {
            let lengths = unlimited_lengths(&c);
            if lengths.iter().all(|&l| l <= MAX_CODE_LENGTH) {
                return Self { lengths };
            }
            for v in c.iter_mut().filter(|v| **v > 0) {
                *v = (*v / 2).max(1);
            }
        }
    }

    /// The code lengths.
    pub fn lengths(&self) -> &[u8; 256] {
        &self.lengths
    }

    /// Canonical codes: `(code, length)` per symbol.
    fn codes(&self) -> [(u16, u8); 256] {
        let mut codes = [(0u16, 0u8); 256];
        let mut code = 0u32;
        for len in 1..=MAX_CODE_LENGTH {
            for (c, &l) in codes.iter_mut().zip(&self.lengths) {
                if l == len {
                    *c = (code as u16, len);
                    code += 1;
                }
            }
            code <<= 1;
        }
        codes
    }

    /// Serializes the lengths, two per byte.
    pub fn to_bytes(&self) -> [u8; TABLE_BYTES] {
        let mut out = [0u8; TABLE_BYTES];
        for (i, pair) in self.lengths.chunks_exact(2).enumerate() {
            out[i] = (pair[0] << 4) | pair[1];
        }
        out
    }

    /// Reads a serialized table and checks that it is a prefix code (Kraft sum ≤ 1).
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        if bytes.len() < TABLE_BYTES {
            return Err(corrupt(format!(
                "Huffman table truncated: {} of {TABLE_BYTES} bytes",
                bytes.len()
            )));
        }
        let mut lengths = [0u8; 256];
        for (i, b) in bytes[..TABLE_BYTES].iter().enumerate() {
            lengths[2 * i] = b >> 4;
            lengths[2 * i + 1] = b & 15;
        }
        let kraft: u64 = lengths
            .iter()
            .filter(|&&l| l > 0)
            .map(|&l| 1u64 << (MAX_CODE_LENGTH - l))
            .sum();
        if kraft > 1 << MAX_CODE_LENGTH {
            return Err(corrupt(
                "Huffman table is over-subscribed (not a prefix code)",
            ));
        }
        Ok(Self { lengths })
    }

    /// Encodes `symbols`; every symbol must have a code.
    pub fn encode(&self, symbols: &[u8]) -> Result<Vec<u8>> {
        let codes = self.codes();
        let mut out = Vec::with_capacity(symbols.len() / 2 + 8);
        let (mut acc, mut bits) = (0u64, 0u32);
        for &s in symbols {
            let (code, len) = codes[s as usize];
            if len == 0 {
                return Err(ReflectanceError::Misuse(format!(
                    "symbol {s} has no code in this table"
                )));
            }
            acc = (acc << len) | code as u64;
            bits += len as u32;
            while bits >= 8 {
                bits -= 8;
                out.push((acc >> bits) as u8);
            }
        }
        if bits > 0 {
            out.push((acc << (8 - bits)) as u8);
        }
        Ok(out)
    }

    /// Decodes exactly `count` symbols from `bytes`.
    pub fn decode(&self, bytes: &[u8], count: usize) -> Result<Vec<u8>> {
        let decoder = Decoder::new(self);
        // Every symbol takes at least one bit: refuse counts the stream cannot hold
        // before allocating for them.
        if count > bytes.len().saturating_mul(8) {
            return Err(corrupt(format!(
                "{count} symbols cannot fit in {} bytes",
                bytes.len()
            )));
        }
        let mut reader = BitReader::new(bytes);
        let mut out = Vec::with_capacity(count);
        for _ in 0..count {
            out.push(decoder.next(&mut reader)?);
        }
        Ok(out)
    }
}

/// Reads bits most significant first; past the end it yields zeros but remembers that it
/// overran, so that a truncated stream is reported.
struct BitReader<'a> {
    bytes: &'a [u8],
    pos: usize,
    acc: u64,
    bits: u32,
}

impl<'a> BitReader<'a> {
    fn new(bytes: &'a [u8]) -> Self {
        Self {
            bytes,
            pos: 0,
            acc: 0,
            bits: 0,
        }
    }

    #[inline]
    fn refill(&mut self) {
        while self.bits <= 56 {
            let b = self.bytes.get(self.pos).copied().unwrap_or(0);
            self.pos += 1;
            self.acc |= (b as u64) << (56 - self.bits);
            self.bits += 8;
        }
    }

    #[inline]
    fn peek(&mut self, n: u8) -> u32 {
        self.refill();
        (self.acc >> (64 - n as u32)) as u32
    }

    #[inline]
    fn consume(&mut self, n: u8) -> Result<()> {
        self.acc <<= n;
        self.bits -= n as u32;
        let total_bits = self.bytes.len() as u64 * 8;
        let read = self.pos as u64 * 8 - self.bits as u64;
        if read > total_bits {
            return Err(corrupt("Huffman stream ends early (truncated)"));
        }
        Ok(())
    }
}

struct Decoder {
    /// For each `FAST_BITS`-bit prefix: (symbol, length), length 0 = longer or invalid.
    fast: Vec<(u8, u8)>,
    /// Symbols sorted by (length, symbol); counts of codes per length.
    sorted: Vec<u8>,
    count: [u16; MAX_CODE_LENGTH as usize + 1],
}

impl Decoder {
    fn new(table: &HuffmanTable) -> Self {
        let mut fast = vec![(0u8, 0u8); 1 << FAST_BITS];
        for (s, &(code, len)) in table.codes().iter().enumerate() {
            if len == 0 || len > FAST_BITS {
                continue;
            }
            let shift = FAST_BITS - len;
            let first = (code as usize) << shift;
            for e in &mut fast[first..first + (1 << shift)] {
                *e = (s as u8, len);
            }
        }
        let mut count = [0u16; MAX_CODE_LENGTH as usize + 1];
        let mut sorted = Vec::new();
        for len in 1..=MAX_CODE_LENGTH {
            for s in 0..256 {
                if table.lengths[s] == len {
                    count[len as usize] += 1;
                    sorted.push(s as u8);
                }
            }
        }
        Self {
            fast,
            sorted,
            count,
        }
    }

    #[inline]
    fn next(&self, r: &mut BitReader) -> Result<u8> {
        let (s, len) = self.fast[r.peek(FAST_BITS) as usize];
        if len > 0 {
            r.consume(len)?;
            return Ok(s);
        }
        // Canonical walk (as in zlib's puff): codes of each length are consecutive.
        let bits = r.peek(MAX_CODE_LENGTH);
        let (mut code, mut first, mut index) = (0u32, 0u32, 0u32);
        for len in 1..=MAX_CODE_LENGTH {
            code |= (bits >> (MAX_CODE_LENGTH - len)) & 1;
            let n = self.count[len as usize] as u32;
            if code < first + n {
                r.consume(len)?;
                return Ok(self.sorted[(index + code - first) as usize]);
            }
            index += n;
            first = (first + n) << 1;
            code <<= 1;
        }
        Err(corrupt("Huffman stream holds a code that no symbol owns"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn counts(symbols: &[u8]) -> [u64; 256] {
        let mut c = [0u64; 256];
        for &s in symbols {
            c[s as usize] += 1;
        }
        c
    }

    proptest! {
        #[test]
        fn round_trip(symbols in proptest::collection::vec(any::<u8>(), 0..3000)) {
            let table = HuffmanTable::from_counts(&counts(&symbols));
            let back = HuffmanTable::from_bytes(&table.to_bytes()).unwrap();
            prop_assert_eq!(&back, &table);
            let bits = table.encode(&symbols).unwrap();
            prop_assert_eq!(back.decode(&bits, symbols.len()).unwrap(), symbols);
        }

        /// A valid table and stream, then damaged: a flipped bit in the table is refused
        /// or yields a table that still decodes `count` symbols or errors; a damaged or cut
        /// stream decodes to exactly `count` symbols or is refused. Random bytes would
        /// rarely pass the Kraft test, so the decoder itself would go untested.
        #[test]
        fn damaged_tables_and_streams_decode_or_are_refused(
            symbols in proptest::collection::vec(0u8..40, 1..2000),
            table_bit in 0usize..TABLE_BYTES * 8,
            stream_flips in proptest::collection::vec((any::<prop::sample::Index>(), 0u8..8), 0..4),
            cut in 0usize..8,
        ) {
            let table = HuffmanTable::from_counts(&counts(&symbols));
            let bits = table.encode(&symbols).unwrap();
            let mut table_bytes = table.to_bytes();
            table_bytes[table_bit / 8] ^= 1 << (table_bit % 8);
            if let Ok(t) = HuffmanTable::from_bytes(&table_bytes)
                && let Ok(out) = t.decode(&bits, symbols.len())
            {
                prop_assert_eq!(out.len(), symbols.len());
            }
            let mut stream = bits.clone();
            for (at, bit) in stream_flips.iter().filter(|_| !bits.is_empty()) {
                let i = at.index(stream.len());
                stream[i] ^= 1 << bit;
            }
            stream.truncate(stream.len().saturating_sub(cut));
            match table.decode(&stream, symbols.len()) {
                Ok(out) => {
                    prop_assert_eq!(out.len(), symbols.len());
                    if stream_flips.is_empty() && cut == 0 {
                        prop_assert_eq!(out, symbols);
                    }
                }
                Err(e) => prop_assert!(matches!(e, ReflectanceError::Corrupt(_)), "{}", e),
            }
        }
    }

    #[test]
    fn skewed_counts_are_length_limited_and_compress() {
        // Fibonacci-like counts force a deep plain Huffman tree.
        let mut c = [0u64; 256];
        let (mut a, mut b) = (1u64, 1u64);
        for v in c.iter_mut().take(40) {
            *v = a;
            (a, b) = (b, a + b);
        }
        let table = HuffmanTable::from_counts(&c);
        assert!(table.lengths().iter().all(|&l| l <= MAX_CODE_LENGTH));
        assert!(table.lengths()[..40].iter().all(|&l| l > 0));
        // A peaked source codes well below 8 bits per symbol.
        let symbols: Vec<u8> = (0..10_000u32)
            .map(|i| if i % 10 == 0 { (i % 7) as u8 } else { 0 })
            .collect();
        let t = HuffmanTable::from_counts(&counts(&symbols));
        let bytes = t.encode(&symbols).unwrap();
        assert!(bytes.len() * 8 < symbols.len() * 2, "{} bytes", bytes.len());
    }

    #[test]
    fn bad_tables_and_streams_are_refused() {
        // Three symbols of length 1: over-subscribed.
        let mut bytes = [0u8; TABLE_BYTES];
        bytes[0] = 0x11;
        bytes[1] = 0x10;
        let e = HuffmanTable::from_bytes(&bytes).unwrap_err().to_string();
        assert!(e.contains("over-subscribed"), "{e}");
        let e = HuffmanTable::from_bytes(&bytes[..10])
            .unwrap_err()
            .to_string();
        assert!(e.contains("truncated") && e.contains("10 of 128"), "{e}");
        let symbols = vec![1u8, 2, 3, 1, 1, 1, 2];
        let table = HuffmanTable::from_counts(&counts(&symbols));
        let bits = table.encode(&symbols).unwrap();
        let e = table
            .decode(&bits[..bits.len() - 1], symbols.len())
            .unwrap_err()
            .to_string();
        assert!(e.contains("ends early"), "{e}");
        let e = table.decode(&bits, 1_000_000).unwrap_err().to_string();
        assert!(
            e.contains("1000000 symbols") && e.contains("2 bytes"),
            "{e}"
        );
        let e = table.encode(&[200]).unwrap_err().to_string();
        assert!(e.contains("symbol 200"), "{e}");
        // A one-symbol table whose stream holds the unassigned code.
        let single = HuffmanTable::from_counts(&counts(&[7, 7, 7]));
        let e = single.decode(&[0xFF], 1).unwrap_err().to_string();
        assert!(e.contains("no symbol owns"), "{e}");
        assert_eq!(single.decode(&[0x00], 3).unwrap(), vec![7, 7, 7]);
    }
}
