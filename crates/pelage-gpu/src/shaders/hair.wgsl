// Real-time strands: the GPU groom's hairs (groom.wgsl's points, xyz and
// width, point-major) drawn as camera-facing ribbons, two triangles a
// segment, pulled from the points buffer by vertex index (no vertex
// buffers: the compute pass's output is drawn as it is).
//
// The ribbons and the hair model are pelage-shaders' hair_math.wgsl
// (placed before this file), the same Bevy's strands use.
//
// Self-shadowing: a deep opacity map (Yuksel & Keyser 2008). From the
// key light: first the depth of the first hair each texel sees; then every
// hair's coverage of its texel added into four layers below that depth
// (the channels of one texture: hairs within `layer_depth`, 2×, 4×, 8× of
// it, each layer counting all before it). A point's light is
// exp(−opacity above it), its opacity interpolated between the layers:
// hairs under many others are dark, hairs in a sparse halo keep their
// light. The skin is opaque: its own depth map puts what lies behind it
// in its shadow.

// Mirrors StrandUniforms in hair_render.rs (a test checks names and offsets).
struct Strands {
    view_proj: mat4x4<f32>,
    // The key light's orthographic clip from world (its shadow map).
    light_view_proj: mat4x4<f32>,
    eye: vec3<f32>,
    focal_length_px: f32,
    // Unit direction towards the key light.
    light_dir: vec3<f32>,
    // Every width's factor (a level of detail's 1/sqrt(fraction)).
    width_scale: f32,
    // Hairs without colours take this one.
    base_color: vec3<f32>,
    // R's strength.
    specular: f32,
    viewport_px: vec2<f32>,
    // The points buffer's row stride (hairs in all) and points a hair.
    stride: u32,
    points: u32,
    // The first render hair in the points buffer.
    first: u32,
    // World units below the first hair or skin the first opacity layer
    // ends at (the next end at 2×, 4×, 8×).
    layer_depth: f32,
    // World units the shadow map's depth range spans.
    shadow_range: f32,
    // Shadow-map texels a world unit (ribbons there are at least one wide).
    shadow_px_per_unit: f32,
    // The highlights' longitudinal shift (Marschner's alpha_R, radians,
    // negative: toward the root) and width (beta_R).
    shift: f32,
    roughness: f32,
    // TRT's strength and the light every hair gets without the key light.
    trt: f32,
    ambient: f32,
    // TT's strength and its azimuthal lobe's exponent.
    transmission: f32,
    transmission_exponent: f32,
    // 1: read the shadow map.
    shadowed: u32,
    // The shadow map's side in texels.
    shadow_size: f32,
    // The share of the key light a hair stops (the rest goes through,
    // forward).
    hair_opacity: f32,
    // The strands' opacity (a cross-fade with shell fur).
    opacity: f32,
    pad1: u32,
    pad2: u32,
};

@group(0) @binding(0) var<uniform> u: Strands;
@group(1) @binding(0) var<storage, read> points: array<vec4<f32>>;
// A render hair's point: rgb (negative: none) and opacity.
@group(1) @binding(1) var<storage, read> colors: array<vec4<f32>>;
// The skin the hairs grow on (a vertex's position, then its normal) and
// its triangles: it shadows the hairs too.
@group(1) @binding(2) var<storage, read> skin: array<vec4<f32>>;
@group(1) @binding(3) var<storage, read> triangles: array<u32>;
// The key light's first hair depth, the opacity layers below it, and
// the skin's depth.
@group(2) @binding(0) var shadow_map: texture_depth_2d;
@group(2) @binding(1) var opacity_map: texture_2d<f32>;
@group(2) @binding(2) var skin_shadow_map: texture_depth_2d;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) tangent: vec3<f32>,
    @location(1) world: vec3<f32>,
    @location(2) coverage: f32,
    @location(3) color: vec4<f32>,
};

struct Corner {
    a: vec4<f32>,
    b: vec4<f32>,
    t: f32,
    side: f32,
    // The render hair and the segment's first point.
    hair: u32,
    j: u32,
};

// Vertex `vertex` of the ribbons: its segment's two points and its corner.
fn corner(vertex: u32) -> Corner {
    let r = ribbon_corner(vertex, u.points);
    var c: Corner;
    c.hair = r.hair;
    c.j = r.j;
    c.t = r.t;
    c.side = r.side;
    let h = u.first + c.hair;
    c.a = points[c.j * u.stride + h];
    c.b = points[(c.j + 1u) * u.stride + h];
    c.a.w *= u.width_scale;
    c.b.w *= u.width_scale;
    return c;
}

// The ribbon's corner in clip space (hair_math's ribbon_clip).
fn expand(c: Corner, view_proj: mat4x4<f32>, half_size: vec2<f32>, px_per_unit: f32) -> vec4<f32> {
    return ribbon_clip(c.a, c.b, c.t, c.side, view_proj, half_size, px_per_unit);
}

@vertex
fn vs_main(@builtin(vertex_index) vertex: u32) -> VertexOut {
    let c = corner(vertex);
    let half_size = 0.5 * u.viewport_px;
    var out: VertexOut;
    out.clip = expand(c, u.view_proj, half_size, u.focal_length_px);
    let p = mix(c.a.xyz, c.b.xyz, c.t);
    let clip_w = (u.view_proj * vec4<f32>(p, 1.0)).w;
    out.coverage = ribbon_coverage(mix(c.a.w, c.b.w, c.t), u.focal_length_px, clip_w);
    out.tangent = c.b.xyz - c.a.xyz;
    out.world = p;
    let at = c.hair * u.points + c.j;
    out.color = mix(colors[at], colors[at + 1u], c.t);
    return out;
}

struct ShadowOut {
    @builtin(position) clip: vec4<f32>,
    // The light the ribbon stops in its texel: its share of the texel
    // times the share a hair stops.
    @location(0) coverage: f32,
};

// The ribbons as the key light sees them.
@vertex
fn vs_shadow(@builtin(vertex_index) vertex: u32) -> ShadowOut {
    let c = corner(vertex);
    var out: ShadowOut;
    out.clip = expand(c, u.light_view_proj, vec2<f32>(0.5 * u.shadow_size), u.shadow_px_per_unit);
    out.coverage = u.hair_opacity * ribbon_coverage(mix(c.a.w, c.b.w, c.t), u.shadow_px_per_unit, 1.0);
    return out;
}

// The skin as the key light sees it: depth only.
@vertex
fn vs_occluder(@builtin(vertex_index) vertex: u32) -> @builtin(position) vec4<f32> {
    return u.light_view_proj * vec4<f32>(skin[2u * triangles[vertex]].xyz, 1.0);
}

// Layer k (0 to 3) ends this far below the first depth, in world units.
fn layer_end(k: u32) -> f32 {
    return u.layer_depth * f32(1u << k);
}

// A fragment's opacity, added to every layer that ends below it.
@fragment
fn fs_opacity(v: ShadowOut) -> @location(0) vec4<f32> {
    let first = textureLoad(shadow_map, vec2<i32>(v.clip.xy), 0);
    let below = max(v.clip.z - first, 0.0) * u.shadow_range;
    var out = vec4<f32>(0.0);
    for (var k = 0u; k < 4u; k++) {
        out[k] = select(0.0, v.coverage, below <= layer_end(k));
    }
    return out;
}

// The opacity above `below` (world units under the first depth) from a
// texel's layers: linear within each layer, the last layer's beyond it.
fn opacity_above(layers: vec4<f32>, below: f32) -> f32 {
    if below <= layer_end(0u) {
        return layers[0] * below / layer_end(0u);
    }
    for (var k = 1u; k < 4u; k++) {
        if below <= layer_end(k) {
            let f = (below - layer_end(k - 1u)) / (layer_end(k) - layer_end(k - 1u));
            return mix(layers[k - 1u], layers[k], f);
        }
    }
    return layers[3];
}

// The key light left at `world` under what lies above it (1: nothing).
fn light_reaching(world: vec3<f32>) -> f32 {
    if u.shadowed == 0u {
        return 1.0;
    }
    let clip = u.light_view_proj * vec4<f32>(world, 1.0);
    let size = vec2<i32>(textureDimensions(shadow_map));
    let uv = vec2<f32>(0.5 * clip.x + 0.5, 0.5 - 0.5 * clip.y);
    let texel = vec2<i32>(uv * vec2<f32>(size));
    // 3×3 texels: a soft edge.
    var sum = 0.0;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let at = clamp(texel + vec2<i32>(dx, dy), vec2<i32>(0), size - 1);
            let first = textureLoad(shadow_map, at, 0);
            let below = max(clip.z - first, 0.0) * u.shadow_range;
            // Behind the skin (past a hair's width of rounding): no light.
            let skin_below = (clip.z - textureLoad(skin_shadow_map, at, 0)) * u.shadow_range;
            let open = select(1.0, 0.0, skin_below > 2.0 / u.shadow_px_per_unit);
            sum += open * exp(-opacity_above(textureLoad(opacity_map, at, 0), below));
        }
    }
    return sum / 9.0;
}

@fragment
fn fs_main(v: VertexOut) -> @location(0) vec4<f32> {
    let t = normalize(v.tangent);
    let l = u.light_dir;
    let to_eye = normalize(u.eye - v.world);
    var base = u.base_color;
    if v.color.r >= 0.0 {
        base = v.color.rgb;
    }
    let lit = light_reaching(v.world);
    var lobes: HairLobes;
    lobes.specular = u.specular;
    lobes.shift = u.shift;
    lobes.roughness = u.roughness;
    lobes.trt = u.trt;
    lobes.transmission = u.transmission;
    lobes.transmission_exponent = u.transmission_exponent;
    let color = base * u.ambient + hair_radiance(t, l, to_eye, base, lobes) * lit;
    return vec4<f32>(color, v.coverage * v.color.a * u.opacity);
}
