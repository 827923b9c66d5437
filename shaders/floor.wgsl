// The memory floor of a frame: one texel fetch per pixel from the pose's pre-lit views
// (a layer and texel that move with the pixel, so neighbouring pixels share cache lines
// as the frame pass's do), written to the frame's target. Nothing renders faster on a
// device; `frf bench interp` reports every variant's time against it. Compiled after
// `common.wgsl`.

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(2) var target_image: texture_storage_2d_array<rgba32float, write>;
// The shared pages of pre-lit codes (`render/src/gpu/prelit.rs`); the pose's from word
// `frame.prelit.y`.
@group(1) @binding(0) var<storage, read> prelit: array<u32>;

fn fetch(pixel: vec2<u32>) -> vec4<f32> {
    let size = frame.crop_size;
    let p = pixel % size;
    let layer = (pixel.x / size.x) % (frame.columns * frame.rows);
    let code = prelit[frame.prelit.y + (layer * size.y + p.y) * size.x + p.x];
    let t = vec4<u32>(code & 255u, (code >> 8u) & 255u, (code >> 16u) & 255u, code >> 24u);
    return vec4<f32>(t) * (1.0 / 255.0);
}

@fragment
fn fs_floor(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    return fetch(vec2<u32>(position.xy));
}

@compute @workgroup_size(8, 8)
fn cs_floor(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= frame.size.x || id.y >= frame.size.y) {
        return;
    }
    textureStore(target_image, id.xy, 0, fetch(id.xy));
}
