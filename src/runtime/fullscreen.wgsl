// The full-screen triangle every fragment pass draws (`gpu::fullscreen_pipeline`'s vertex entry point): three
// vertices covering clip space, no vertex buffer. Prepended to each full-screen pass's WGSL by its Rust module
// (`concat!(include_str!(".../fullscreen.wgsl"), include_str!("pass.wgsl"))`); WGSL has no include of its own.

@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let x = f32((i << 1u) & 2u);
    let y = f32(i & 2u);
    return vec4<f32>(x * 2.0 - 1.0, 1.0 - y * 2.0, 0.0, 1.0);
}
