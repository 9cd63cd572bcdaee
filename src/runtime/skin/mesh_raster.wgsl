// The mesh G-buffer pass (runtime/skin/mesh_raster.rs): rasterises a triangle mesh with a depth buffer and writes, per
// pixel, the view-space unit normal and the linear view depth in mm (target 0), the texture coordinates with a
// coverage flag (target 1) and the view-space tangent with its handedness (target 2, mesh/tangents.rs). Its CPU
// twin is runtime/skin/mesh_raster_cpu.rs.

struct Camera {
    view_proj: mat4x4<f32>,
    view: mat4x4<f32>,
    // x: mm per mesh unit
    params: vec4<f32>,
};

@group(0) @binding(0) var<uniform> cam: Camera;

struct VsIn {
    @location(0) pos: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) tangent: vec4<f32>,
};

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) n_view: vec3<f32>,
    @location(1) depth_mm: f32,
    @location(2) uv: vec2<f32>,
    @location(3) t_view: vec4<f32>,
};

@vertex
fn vs_mesh(v: VsIn) -> VsOut {
    var o: VsOut;
    let p = vec4<f32>(v.pos, 1.0);
    o.clip = cam.view_proj * p;
    o.n_view = (cam.view * vec4<f32>(v.normal, 0.0)).xyz;
    o.depth_mm = -(cam.view * p).z * cam.params.x;
    o.uv = v.uv;
    o.t_view = vec4<f32>((cam.view * vec4<f32>(v.tangent.xyz, 0.0)).xyz, v.tangent.w);
    return o;
}

struct GBuffer {
    @location(0) normal_depth: vec4<f32>,
    @location(1) uv_cover: vec4<f32>,
    @location(2) tangent: vec4<f32>,
};

@fragment
fn fs_mesh(i: VsOut) -> GBuffer {
    var g: GBuffer;
    g.normal_depth = vec4<f32>(normalize(i.n_view), i.depth_mm);
    g.uv_cover = vec4<f32>(i.uv, 1.0, 0.0);
    g.tangent = i.t_view;
    return g;
}
