//! A small binary glTF 2.0 writer: one buffer (the GLB's binary chunk) of 4-byte
//! aligned views, accessors, images, and a JSON document the caller fills; and the GLB
//! container both ways ([`pack`], [`unpack`]), its layout named once here.

use serde_json::{Value, json};

/// A GLB being built.
#[derive(Debug, Default)]
pub struct Glb {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    images: Vec<Value>,
}

/// glTF's component types.
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;

impl Glb {
    /// Appends bytes as a buffer view; its index. `target`: a vertex (34962) or index
    /// (34963) buffer, or none (images).
    pub fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut v = json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()});
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        self.bin.extend_from_slice(bytes);
        self.views.push(v);
        self.views.len() - 1
    }

    /// A VEC3 float accessor of `points` (with the bounds glTF requires of positions).
    pub fn vec3(&mut self, points: &[[f32; 3]]) -> usize {
        let mut bytes = Vec::with_capacity(points.len() * 12);
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for p in points {
            for c in 0..3 {
                bytes.extend_from_slice(&p[c].to_le_bytes());
                lo[c] = lo[c].min(p[c]);
                hi[c] = hi[c].max(p[c]);
            }
        }
        let view = self.view(&bytes, Some(34962));
        self.accessors.push(json!({
            "bufferView": view, "componentType": FLOAT, "count": points.len(),
            "type": "VEC3", "min": lo, "max": hi
        }));
        self.accessors.len() - 1
    }

    /// A SCALAR float accessor (animation inputs and outputs carry bounds).
    pub fn scalars(&mut self, values: &[f32]) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes, None);
        let lo = values.iter().copied().fold(f32::INFINITY, f32::min);
        let hi = values.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        self.accessors.push(json!({
            "bufferView": view, "componentType": FLOAT, "count": values.len(),
            "type": "SCALAR", "min": [lo], "max": [hi]
        }));
        self.accessors.len() - 1
    }

    /// A VEC3 float accessor without bounds (animation outputs).
    pub fn vec3_values(&mut self, values: &[[f32; 3]]) -> usize {
        let bytes: Vec<u8> = values
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let view = self.view(&bytes, None);
        self.accessors.push(json!({
            "bufferView": view, "componentType": FLOAT, "count": values.len(), "type": "VEC3"
        }));
        self.accessors.len() - 1
    }

    /// A SCALAR u32 index accessor.
    pub fn indices(&mut self, indices: &[u32]) -> usize {
        let bytes: Vec<u8> = indices.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(34963));
        self.accessors.push(json!({
            "bufferView": view, "componentType": UNSIGNED_INT, "count": indices.len(),
            "type": "SCALAR"
        }));
        self.accessors.len() - 1
    }

    /// An image of encoded bytes (`image/png` or `image/jpeg`); its index.
    pub fn image(&mut self, bytes: &[u8], mime: &str, name: String) -> usize {
        let view = self.view(bytes, None);
        self.images
            .push(json!({"bufferView": view, "mimeType": mime, "name": name}));
        self.images.len() - 1
    }

    /// Bytes of the binary chunk so far.
    pub fn binary_bytes(&self) -> usize {
        self.bin.len()
    }

    /// The GLB file: `document` completed with the buffer, views, accessors and images.
    pub fn finish(mut self, mut document: Value) -> Vec<u8> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        document["buffers"] = json!([{"byteLength": self.bin.len()}]);
        document["bufferViews"] = Value::Array(self.views);
        document["accessors"] = Value::Array(self.accessors);
        if !self.images.is_empty() {
            document["images"] = Value::Array(self.images);
        }
        pack(&document, &self.bin)
    }
}

/// The container's magic, first in the file.
pub const MAGIC: &[u8; 4] = b"glTF";
/// The container's version.
pub const CONTAINER_VERSION: u32 = 2;
/// Bytes of the file's header (magic, version, total length).
pub const HEADER_BYTES: usize = 12;
/// Bytes of a chunk's header (length, type).
pub const CHUNK_HEADER_BYTES: usize = 8;
/// The JSON chunk's type.
pub const JSON_CHUNK: &[u8; 4] = b"JSON";
/// The binary chunk's type.
pub const BIN_CHUNK: &[u8; 4] = b"BIN\0";

/// A GLB container of `document` and the binary chunk `bin` (whose length is a multiple of
/// four): the header, the JSON chunk padded with spaces, the binary chunk.
pub fn pack(document: &Value, bin: &[u8]) -> Vec<u8> {
    let mut text = serde_json::to_vec(document).expect("a JSON value serializes");
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let total = HEADER_BYTES + CHUNK_HEADER_BYTES + text.len() + CHUNK_HEADER_BYTES + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&CONTAINER_VERSION.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(text.len() as u32).to_le_bytes());
    out.extend_from_slice(JSON_CHUNK);
    out.extend_from_slice(&text);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(BIN_CHUNK);
    out.extend_from_slice(bin);
    out
}

/// The JSON document and the binary chunk of a GLB container, checked whole; what is
/// wrong with it otherwise.
pub fn unpack(bytes: &[u8]) -> Result<(Value, &[u8]), String> {
    let word = |at: usize| -> Option<u32> {
        bytes
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    if bytes.get(0..4) != Some(MAGIC.as_slice()) {
        return Err("not a binary glTF file (no glTF magic)".into());
    }
    if word(4) != Some(CONTAINER_VERSION) {
        return Err(format!(
            "glTF container version {:?}, expected {CONTAINER_VERSION}",
            word(4)
        ));
    }
    let total = word(8).unwrap_or(0) as usize;
    if total != bytes.len() {
        return Err(format!(
            "its header says {total} bytes and it has {}: truncated or appended to",
            bytes.len()
        ));
    }
    let json_at = HEADER_BYTES + CHUNK_HEADER_BYTES;
    let json_len = word(HEADER_BYTES).ok_or("no JSON chunk")? as usize;
    if bytes.get(HEADER_BYTES + 4..json_at) != Some(JSON_CHUNK.as_slice())
        || json_at + json_len > bytes.len()
    {
        return Err("the first chunk is not a whole JSON chunk".into());
    }
    let document: Value = serde_json::from_slice(&bytes[json_at..json_at + json_len])
        .map_err(|e| format!("its JSON chunk does not parse: {e}"))?;
    let at = json_at + json_len;
    let bin_len = word(at).ok_or("no binary chunk")? as usize;
    let bin_at = at + CHUNK_HEADER_BYTES;
    if bytes.get(at + 4..bin_at) != Some(BIN_CHUNK.as_slice()) || bin_at + bin_len > bytes.len() {
        return Err("the second chunk is not a whole binary chunk".into());
    }
    Ok((document, &bytes[bin_at..bin_at + bin_len]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_container_unpacks_to_what_was_packed_and_a_cut_one_is_refused() {
        let document = json!({"asset": {"version": "2.0"}, "odd": "x"});
        let bin = [1u8, 2, 3, 4, 5, 6, 7, 8];
        let bytes = pack(&document, &bin);
        let (back, chunk) = unpack(&bytes).unwrap();
        assert_eq!((back, chunk), (document, &bin[..]));
        let cut = unpack(&bytes[..bytes.len() - 4]).unwrap_err();
        assert!(cut.contains("truncated"), "{cut}");
        let mut other = bytes.clone();
        other[0] = b'x';
        assert!(unpack(&other).unwrap_err().contains("no glTF magic"));
    }
}
