// The line tiles of the compute forms of the separable and the Gaussian blurs (separable_tiled.wgsl,
// gaussian_tiled.wgsl; prepended by their Rust modules): a workgroup of SEGMENT threads blurs SEGMENT texels of one row
// (or column) and holds them with an APRON either side in workgroup memory, colour in `tile_color`; both read the
// linear depth at binding 2 and write the result through the storage texture at binding 3.

@group(0) @binding(2) var depth_tex: texture_2d<f32>;
@group(0) @binding(3) var out_tex: texture_storage_2d<rgba16float, write>;

const SEGMENT: i32 = 128;
const APRON: i32 = 64;
const SLOTS: i32 = 256; // SEGMENT + 2 · APRON

var<workgroup> tile_color: array<vec4<f32>, 256>;

// The texel at position `along` of line `line`: of a row when `horizontal`, else of a column.
fn line_texel(along: i32, line: i32, horizontal: bool) -> vec2<i32> {
    if (horizontal) {
        return vec2<i32>(along, line);
    }
    return vec2<i32>(line, along);
}
