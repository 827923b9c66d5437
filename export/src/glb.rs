//! A small binary glTF 2.0 writer: one buffer (the GLB's binary chunk) of 4-byte
//! aligned views, accessors, images, and a JSON document the caller fills.

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

/// A GLB container of `document` and the binary chunk `bin` (whose length is a multiple of
/// four): the header, the JSON chunk padded with spaces, the binary chunk.
pub fn pack(document: &Value, bin: &[u8]) -> Vec<u8> {
    let mut text = serde_json::to_vec(document).expect("a JSON value serializes");
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let total = 12 + 8 + text.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(text.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&text);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(bin);
    out
}
