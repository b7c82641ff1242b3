// The uniform block every preview shader reads; prepended to each shader's
// source (see SHADERS in lib.rs), so it is defined once.

struct Frame {
    view_proj: mat4x4<f32>,
    // xyz: direction towards the light (unit).
    light_dir: vec4<f32>,
    // rgb: skin colour.
    skin_color: vec4<f32>,
    // rgb: point colour, a: point radius in pixels.
    point_color: vec4<f32>,
    // xy: viewport size in pixels, z: depth pull towards the camera for
    // points (in clip w units), w: focal length in pixels.
    viewport: vec4<f32>,
    // xyz: camera position.
    eye: vec4<f32>,
    // rgb: hair colour, a: specular strength.
    hair_color: vec4<f32>,
};

@group(0) @binding(0) var<uniform> frame: Frame;
