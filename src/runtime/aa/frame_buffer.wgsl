// A frame held on the device as packed RGBA8 in a storage buffer (one u32 per pixel, R in the low byte, top row
// first, sRGB-encoded: what the skin frame's compute chains leave for their read-back) carried into the colour
// texture the antialiasing passes read (`cs_unpack`) and their output carried back into the buffer (`cs_pack`), so
// a frame is antialiased in the encoder that shaded it (runtime/aa/three_pass.rs, `ThreePass::encode_on_buffer`).
// Both conversions are exact: unpack4x8unorm gives b/255, which an rgba8unorm store and pack4x8unorm round back to b.

@group(0) @binding(0) var<storage, read_write> frame: array<u32>;
@group(0) @binding(1) var colour_out: texture_storage_2d<rgba8unorm, write>;
@group(0) @binding(2) var aa_in: texture_2d<f32>;

@compute @workgroup_size(8, 8)
fn cs_unpack(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(colour_out);
    if (any(id.xy >= size)) {
        return;
    }
    textureStore(colour_out, id.xy, unpack4x8unorm(frame[id.y * size.x + id.x]));
}

@compute @workgroup_size(8, 8)
fn cs_pack(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(aa_in);
    if (any(id.xy >= size)) {
        return;
    }
    frame[id.y * size.x + id.x] = pack4x8unorm(textureLoad(aa_in, vec2<i32>(id.xy), 0));
}
