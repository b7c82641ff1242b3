// The uniform block every preview shader reads; prepended to each shader's
// source (see SHADERS in lib.rs), so it is defined once.

// Mirrors FrameUniforms in renderer.rs (a test checks names and offsets).
struct Frame {
    view_proj: mat4x4<f32>,
    eye: vec3<f32>,
    // Point disc radius in pixels.
    point_radius: f32,
    // Unit direction towards the light.
    light_dir: vec3<f32>,
    // Depth pull towards the camera for points, in clip w units.
    point_depth_pull: f32,
    skin_color: vec3<f32>,
    focal_length_px: f32,
    point_color: vec3<f32>,
    hair_specular: f32,
    hair_color: vec3<f32>,
    pad0: f32,
    viewport_px: vec2<f32>,
    pad1: vec2<f32>,
};

@group(0) @binding(0) var<uniform> frame: Frame;
