// Real-time strands in Bevy's main 3D pass (pelage-bevy's StrandMaterial):
// the groom's hairs as the GPU grew them this frame (pelage's groom.wgsl,
// dispatched before this pass; world space, point-major), drawn as
// camera-facing ribbons pulled by vertex number, shaded with pelage's hair
// model (Kajiya-Kay with Marschner's R, TRT and TT lobes) under each of
// the scene's directional lights. The ribbons and the model are pelage's
// shared hair_math.wgsl, the same pelage-gpu draws with.

#import bevy_pbr::mesh_view_bindings::{view, lights}
#import pelage::hair_math::{ribbon_corner, ribbon_clip, ribbon_coverage, HairLobes, hair_radiance}
#ifdef TONEMAP_IN_SHADER
#import bevy_core_pipeline::tonemapping::tone_mapping
#endif

// Mirrors StrandUniform in hair_material.rs (encase lays it out).
struct Strands {
    // Hairs in the points buffer (its rows' stride) and points a hair.
    stride: u32,
    points: u32,
    // The first render hair, and the render hairs drawn.
    first: u32,
    drawn: u32,
    // Every width's factor, and the strands' opacity.
    width_scale: f32,
    opacity: f32,
    // R's strength and the highlights' shift.
    specular: f32,
    shift: f32,
    // Hairs without colours take this one.
    base_color: vec3<f32>,
    roughness: f32,
    trt: f32,
    transmission: f32,
    transmission_exponent: f32,
    pad: f32,
};

@group(#{MATERIAL_BIND_GROUP}) @binding(0) var<uniform> strands: Strands;
@group(#{MATERIAL_BIND_GROUP}) @binding(1) var<storage, read> points: array<vec4<f32>>;
// A render hair's point: rgb (negative: none) and opacity.
@group(#{MATERIAL_BIND_GROUP}) @binding(2) var<storage, read> colors: array<vec4<f32>>;

struct Vertex {
    // The vertex's own number in the ribbon mesh.
    @location(0) corner: u32,
};

struct StrandOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) tangent: vec3<f32>,
    @location(1) world: vec3<f32>,
    @location(2) coverage: f32,
    @location(3) color: vec4<f32>,
};

@vertex
fn vertex(v: Vertex) -> StrandOut {
    let c = ribbon_corner(v.corner, strands.points);
    var out: StrandOut;
    if c.hair >= strands.drawn {
        // Not drawn at this level of detail: every corner on one point,
        // so its triangles cover nothing.
        out.clip = vec4<f32>(0.0, 0.0, -1.0, 1.0);
        return out;
    }
    let h = strands.first + c.hair;
    var a = points[c.j * strands.stride + h];
    var b = points[(c.j + 1u) * strands.stride + h];
    a.w *= strands.width_scale;
    b.w *= strands.width_scale;
    let half_size = 0.5 * view.viewport.zw;
    // The focal length in pixels: a unit at clip w = 1 spans this many.
    let px_per_unit = view.clip_from_view[1][1] * half_size.y;
    out.clip = ribbon_clip(a, b, c.t, c.side, view.clip_from_world, half_size, px_per_unit);
    let p = mix(a.xyz, b.xyz, c.t);
    let clip_w = (view.clip_from_world * vec4<f32>(p, 1.0)).w;
    out.coverage = ribbon_coverage(mix(a.w, b.w, c.t), px_per_unit, clip_w);
    out.tangent = b.xyz - a.xyz;
    out.world = p;
    let at = c.hair * strands.points + c.j;
    out.color = mix(colors[at], colors[at + 1u], c.t);
    return out;
}

@fragment
fn fragment(v: StrandOut) -> @location(0) vec4<f32> {
    let t = normalize(v.tangent);
    let to_eye = normalize(view.world_position - v.world);
    var base = strands.base_color;
    if v.color.r >= 0.0 {
        base = v.color.rgb;
    }
    var lobes: HairLobes;
    lobes.specular = strands.specular;
    lobes.shift = strands.shift;
    lobes.roughness = strands.roughness;
    lobes.trt = strands.trt;
    lobes.transmission = strands.transmission;
    lobes.transmission_exponent = strands.transmission_exponent;
    // Each directional light's radiance through the hair model, as a BRDF
    // (1/π, as the shells and Bevy's PBR surfaces meet the same light).
    var lit = base * lights.ambient_color.rgb;
    for (var i = 0u; i < lights.n_directional_lights; i++) {
        let light = lights.directional_lights[i];
        let radiance = hair_radiance(t, light.direction_to_light, to_eye, base, lobes);
        lit += radiance * light.color.rgb / 3.14159265;
    }
    var out = vec4<f32>(lit * view.exposure, v.coverage * v.color.a * strands.opacity);
#ifdef TONEMAP_IN_SHADER
    out = tone_mapping(out, view.color_grading);
#endif
    return out;
}
