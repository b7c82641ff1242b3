// Shell fur in Bevy's main 3D pass (pelage-bevy's ShellFurMaterial): the
// layers of a fur mesh (the skin's vertices once per layer, `layer` n)
// skinned by Bevy's own joint matrices, pushed out along the strand
// (Silva Eq. 1 with the file's coupling, Banisch Fig. 6), curled (Eq. 4)
// and clumped (Alg. 2) by the wetness mask, textured by
// pelage's shell texture and shaded with Kajiya-Kay (Silva Eq. 6) under
// the scene's directional lights. The math is pelage's shared module
// (pelage-shaders' shell_math.wgsl), the same pelage-gpu runs.
//
// With FUR_POSITION_PROBE (pelage-bevy's probe.rs) the same vertex stage
// runs over points, and each point's fragment stores its vertex's world
// position instead of shading.

#import bevy_pbr::{
    mesh_bindings::mesh,
    mesh_functions,
    skinning,
    mesh_view_bindings::{view, lights, globals},
    view_transformations::position_world_to_clip,
}
#import pelage::shell_math::{
    coupled_offset, coupled_tangent, layer_height, kajiya_kay_lit, shadow_factor,
    curl_offset, curl_tangent, clump_profile, clump_displacement,
}
#ifdef TONEMAP_IN_SHADER
#import bevy_core_pipeline::tonemapping::tone_mapping
#endif

// Mirrors ShellFurUniform in material.rs (encase lays it out).
struct ShellFur {
    // Where the strands' tips are pushed by the dynamics (world units).
    tip_offset: vec3<f32>,
    // L0: the outermost layer's height above the skin (mesh units).
    length: f32,
    // K_s and p_phong.
    specular: vec3<f32>,
    exponent: f32,
    // N: layers of this fur mesh.
    layers: u32,
    // Coupling::index and the bent coupling's k.
    coupling: u32,
    coupling_exponent: f32,
    // Shell texture repeats across the UV square.
    tiles: f32,
    k_shadow: f32,
    // The layers' opacity, 0 to 1.
    opacity: f32,
    // The colour texture's gain (1: as painted).
    color_gain: f32,
    // Bit 0: curl (Eq. 4); bit 1: clumps (Alg. 2).
    effects: u32,
    // K_α (mesh units) and ω of the curl.
    curl_radius: f32,
    curl_frequency: f32,
    // w and the strength of the clump.
    clump_w: f32,
    clump_strength: f32,
    // The wetness mask's size in texels.
    wetness_size: vec2<f32>,
};

@group(#{MATERIAL_BIND_GROUP}) @binding(0) var<uniform> fur: ShellFur;
@group(#{MATERIAL_BIND_GROUP}) @binding(1) var fur_layers: texture_2d_array<f32>;
@group(#{MATERIAL_BIND_GROUP}) @binding(2) var fur_sampler: sampler;
@group(#{MATERIAL_BIND_GROUP}) @binding(3) var color_texture: texture_2d<f32>;
@group(#{MATERIAL_BIND_GROUP}) @binding(4) var color_sampler: sampler;
// pelage's WetnessMask (WetTexel: clump centre xy, radius z, wetness w),
// read at mask coordinates: Bevy's glTF UVs are already those.
@group(#{MATERIAL_BIND_GROUP}) @binding(5) var wetness: texture_2d<f32>;

#ifdef FUR_POSITION_PROBE
// One world position a fur-mesh vertex, and in w the frame that stored
// it (Bevy's frame count, plus 1), so stale ones can be told apart.
@group(#{MATERIAL_BIND_GROUP}) @binding(100) var<storage, read_write> probed: array<vec4<f32>>;
#endif

const CURL: u32 = 1u;
const CLUMP: u32 = 2u;

// WetnessMask::at: nearest texel, clamped.
fn wetness_at(p: vec2<f32>) -> vec4<f32> {
    let size = fur.wetness_size;
    let texel = clamp(floor(p * size), vec2<f32>(0.0), size - 1.0);
    return textureLoad(wetness, vec2<i32>(texel), 0);
}

// Locations as Bevy's mesh pipeline gives them (forward_io's Vertex), and
// the layer at 8 (ATTRIBUTE_SHELL_LAYER).
struct Vertex {
    @builtin(instance_index) instance_index: u32,
    @builtin(vertex_index) index: u32,
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    // dP/du (pelage_shaders::shell::vertex_tangents), w unused.
    @location(4) tangent: vec4<f32>,
#ifdef SKINNED
    @location(6) joint_indices: vec4<u32>,
    @location(7) joint_weights: vec4<f32>,
#endif
    @location(8) layer: u32,
};

struct FurOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) tangent: vec3<f32>,
    @location(3) normal: vec3<f32>,
    @location(4) u_axis: vec3<f32>,
    @location(5) @interpolate(flat) h: f32,
    @location(6) @interpolate(flat) layer: u32,
#ifdef FUR_POSITION_PROBE
    @location(7) @interpolate(flat) probe_world: vec3<f32>,
    // The vertex's index in its fur mesh (Bevy packs meshes into shared
    // buffers: the draw's index counts from the mesh's first vertex).
    @location(8) @interpolate(flat) probe_index: u32,
#endif
};

@vertex
fn vertex(v: Vertex) -> FurOut {
#ifdef SKINNED
    let world_from_local = skinning::skin_model(v.joint_indices, v.joint_weights, v.instance_index);
#else
    let world_from_local = mesh_functions::get_world_from_local(v.instance_index);
#endif
    let h = layer_height(v.layer, fur.layers);
    // Root and rest tip both carried by the skin's matrix, so the strand
    // scales, bends and turns with it as the skin does.
    let root = (world_from_local * vec4<f32>(v.position, 1.0)).xyz;
    let rest_tip = (world_from_local * vec4<f32>(v.position + fur.length * normalize(v.normal), 1.0)).xyz;
    let tip = rest_tip + fur.tip_offset;
    var offset = coupled_offset(fur.coupling, fur.coupling_exponent, root, rest_tip, tip, h);
    var t = coupled_tangent(fur.coupling, fur.coupling_exponent, root, rest_tip, tip, h);
    if dot(t, t) == 0.0 {
        t = rest_tip - root;
    }
    let n = normalize(rest_tip - root);
    let along = (world_from_local * vec4<f32>(v.tangent.xyz, 0.0)).xyz;
    var u = along - n * dot(n, along);
    if dot(u, u) == 0.0 {
        u = vec3<f32>(1.0, 0.0, 0.0);
    }
    u = normalize(u);
    if (fur.effects & CURL) != 0u {
        // K_α is in mesh units; the skin's matrix scales it as the strand.
        let scale = distance(rest_tip, root) / max(fur.length, 1e-12);
        let wet = wetness_at(v.uv).w;
        let k = fur.curl_radius * scale;
        offset += curl_offset(h, wet, k, fur.curl_frequency, u, cross(n, u));
        t += curl_tangent(h, wet, k, fur.curl_frequency, u, cross(n, u));
    }
    var out: FurOut;
    out.world = root + offset;
    out.clip = position_world_to_clip(out.world);
    out.uv = v.uv;
    out.tangent = t;
    out.normal = n;
    out.u_axis = u;
    out.h = h;
    out.layer = v.layer;
#ifdef FUR_POSITION_PROBE
    out.probe_world = out.world;
    out.probe_index = v.index - mesh[v.instance_index].first_vertex_index;
#endif
    return out;
}

#ifdef FUR_POSITION_PROBE
@fragment
fn fragment(v: FurOut) -> @location(0) vec4<f32> {
    probed[v.probe_index] = vec4<f32>(v.probe_world, f32(globals.frame_count) + 1.0);
    return vec4<f32>(0.0);
}
#else
@fragment
fn fragment(v: FurOut) -> @location(0) vec4<f32> {
    var uv_color = v.uv;
    var uv_geo = v.uv * fur.tiles;
    // Derivatives taken before any branch (a clump may discard): the
    // lookups below then need no uniform control flow.
    let geo_dx = dpdx(uv_geo);
    let geo_dy = dpdy(uv_geo);
    let color_dx = dpdx(uv_color);
    let color_dy = dpdy(uv_color);
    // Alg. 2: a wet texel's hairs lean towards its clump's centre; what
    // leaves the clump or lands on dry fur is not drawn.
    if (fur.effects & CLUMP) != 0u {
        let here = wetness_at(v.uv);
        if here.w != 0.0 {
            let profile = clump_profile(v.h, fur.clump_w, fur.layers);
            let d = clump_displacement(profile, fur.clump_strength, here.w, v.uv, here.xy);
            if distance(v.uv, here.xy) > here.z || wetness_at(v.uv + d).w == 0.0 {
                discard;
            }
            uv_color += d;
            uv_geo += d * fur.tiles;
        }
    }
    let shell = textureSampleGrad(fur_layers, fur_sampler, uv_geo, v.layer, geo_dx, geo_dy);
    if shell.a <= 0.0 {
        discard;
    }
    let color = fur.color_gain
        * textureSampleGrad(color_texture, color_sampler, uv_color, color_dx, color_dy).rgb;
    // The strand tangent, leaning with the texel's own hair (x along
    // dP/du, y down the image), as pelage-gpu's fs_layer does.
    let n = normalize(v.normal);
    var u = v.u_axis;
    if dot(u, u) == 0.0 {
        u = vec3<f32>(1.0, 0.0, 0.0);
    }
    u = normalize(u);
    let lean = (2.0 * shell.r - 1.0) * u - (2.0 * shell.g - 1.0) * cross(n, u);
    let t = normalize(normalize(v.tangent) + lean);
    let e = normalize(view.world_position - v.world);
    // Each directional light's radiance through Kajiya-Kay, as a BRDF
    // (1/π, so fur and PBR surfaces beside it meet under the same light).
    var lit = vec3<f32>(0.0);
    for (var i = 0u; i < lights.n_directional_lights; i++) {
        let light = lights.directional_lights[i];
        let k = kajiya_kay_lit(color, t, light.direction_to_light, e, v.h, fur.specular, fur.exponent, fur.k_shadow);
        lit += k * light.color.rgb / 3.14159265;
    }
    lit += shadow_factor(v.h, fur.k_shadow) * color * lights.ambient_color.rgb;
    var out = vec4<f32>(lit * view.exposure, shell.a * fur.opacity);
#ifdef TONEMAP_IN_SHADER
    out = tone_mapping(out, view.color_grading);
#endif
    return out;
}
#endif
