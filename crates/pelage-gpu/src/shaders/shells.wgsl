// The functions of pelage::shell::math come first: pelage-shaders'
// shell_math.wgsl, shared with the Bevy plugin (pelage_shaders::shell).
//
// Shell fur (Silva et al., Lengyel et al., Banisch & Wüthrich): the skin
// drawn once with depth write, then the layers in one instanced draw
// (instance n = layer n), depth test on and write off, blended in layer
// order, then the fins. Every formula mirrors a function of
// pelage::shell::math, named the same; keep them in step (tests/shells.rs
// renders against the Rust; tests/shells_game.rs checks fins and the level
// of detail).

// Mirrors ShellUniforms in shells.rs (a test checks names and offsets).
struct Shell {
    view_proj: mat4x4<f32>,
    // The camera position.
    eye: vec3<f32>,
    // L0: the length of the outermost layer above the skin.
    shell_length: f32,
    // Unit direction towards the light.
    light_dir: vec3<f32>,
    // N: layers drawn.
    layers: u32,
    // K_s.
    specular: vec3<f32>,
    // p_phong.
    specular_exponent: f32,
    // The whole skin moved by this (a shaken object).
    motion: vec3<f32>,
    // Eq. 4's k, for the bent coupling.
    coupling_exponent: f32,
    // Shell texture repeats across the UV square.
    tiles: f32,
    k_shadow: f32,
    // K_α and ω of the curl.
    curl_radius: f32,
    curl_frequency: f32,
    // ShadingMode::index.
    shading_mode: u32,
    // Coupling::index.
    coupling: u32,
    // w and the strength of the clump.
    clump_w: f32,
    clump_strength: f32,
    // The wetness mask's size in texels.
    wetness_size: vec2<f32>,
    // L: this level of detail's layers, continuous (N: full detail).
    lod_layers: f32,
    // The fur texture's mip level.
    fur_mip: f32,
    // Fins: opacity edge-on, and the |n·e| where they have faded out.
    fin_opacity: f32,
    fin_width: f32,
    // The layers' and fins' opacity (a cross-fade with real-time strands).
    fur_opacity: f32,
    pad0: f32,
};

@group(0) @binding(0) var<uniform> shell: Shell;
@group(1) @binding(0) var fur_layers: texture_2d_array<f32>;
@group(1) @binding(1) var fur_sampler: sampler;
@group(1) @binding(2) var color_texture: texture_2d<f32>;
@group(1) @binding(3) var color_sampler: sampler;
@group(1) @binding(4) var wetness: texture_2d<f32>;

// Specialised per pipeline: plain shells, + curl, + curl + clump.
override CURL: bool = true;
override CLUMP: bool = true;

// Mirrors PoseVertex (locations 0-2), SurfaceVertex (3) and TipOffset (4)
// in shells/mod.rs (a test checks names and locations).
struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    // dP/du, the texture's x direction on the surface.
    @location(2) tangent: vec3<f32>,
    // Mask (image) coordinates: (u, 1 − v).
    @location(3) uv: vec2<f32>,
    // p − p0: how far the strand's tip particle has moved (0 at rest).
    @location(4) tip_offset: vec3<f32>,
};

fn kajiya_kay(color: vec3<f32>, t: vec3<f32>, l: vec3<f32>, e: vec3<f32>, h: f32) -> vec3<f32> {
    return kajiya_kay_lit(color, t, l, e, h, shell.specular, shell.specular_exponent, shell.k_shadow);
}

fn shade(color: vec3<f32>, along: f32, t: vec3<f32>, n: vec3<f32>, l: vec3<f32>, e: vec3<f32>, h: f32) -> vec3<f32> {
    let mode = shell.shading_mode;
    if mode == 0u {
        return vec3<f32>(0.5 + 0.5 * along);
    } else if mode == 1u {
        return color;
    } else if mode == 2u {
        return shadow_factor(h, shell.k_shadow) * color;
    } else if mode == 3u {
        return shadow_factor(h, shell.k_shadow) * color * (0.25 + 0.75 * max(dot(n, l), 0.0));
    }
    return kajiya_kay(color, t, l, e, h);
}

// ---- texture access, as pelage::shell reads it ----

// WetnessMask::at: nearest texel, clamped.
fn wetness_at(p: vec2<f32>) -> vec4<f32> {
    let size = shell.wetness_size;
    let texel = clamp(floor(p * size), vec2<f32>(0.0), size - 1.0);
    return textureLoad(wetness, vec2<i32>(texel), 0);
}

// ---- the skin ----

struct SkinOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
};

@vertex
fn vs_skin(v: VertexIn) -> SkinOut {
    var out: SkinOut;
    out.world = v.position + shell.motion;
    out.clip = shell.view_proj * vec4<f32>(out.world, 1.0);
    out.normal = v.normal;
    out.uv = v.uv;
    return out;
}

@fragment
fn fs_skin(v: SkinOut) -> @location(0) vec4<f32> {
    let n = normalize(v.normal);
    let e = normalize(shell.eye - v.world);
    let color = textureSampleLevel(color_texture, color_sampler, v.uv, 0.0).rgb;
    // The skin is the fur at h = 0, the strand leaving along the normal;
    // in the structure view it is the black the hair stands on.
    if shell.shading_mode == 0u {
        return vec4<f32>(0.0, 0.0, 0.0, 1.0);
    }
    return vec4<f32>(shade(color, 0.0, n, n, shell.light_dir, e, 0.0), 1.0);
}

// ---- the layers ----

struct LayerOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) tangent: vec3<f32>,
    @location(3) normal: vec3<f32>,
    @location(4) u_axis: vec3<f32>,
    // h of this layer.
    @location(5) @interpolate(flat) h: f32,
    // clump_profile(h, w, N) of this layer.
    @location(6) @interpolate(flat) clump_profile: f32,
    // The shell texture slice at h: layer n at full detail, between two
    // slices otherwise.
    @location(7) @interpolate(flat) slice: f32,
    // Opacity: the faded-in innermost layer of a level of detail, and the
    // exponent N / L that gives L layers the coverage of N.
    @location(8) @interpolate(flat) fade: f32,
    @location(9) @interpolate(flat) coverage: f32,
};

// The height of layer n of the ⌈L⌉ drawn (n = 0 innermost): layer_height at
// full detail; with L < N layers they stand 1/L apart down from the tip,
// so as L grows they slide apart and a new innermost one fades in.
fn lod_height(n: u32, layers: u32, lod_layers: f32) -> f32 {
    if lod_layers >= f32(layers) {
        return layer_height(n, layers);
    }
    let drawn = u32(ceil(lod_layers));
    return 1.0 - f32(drawn - 1u - n) / lod_layers;
}

@vertex
fn vs_layer(v: VertexIn, @builtin(instance_index) layer: u32) -> LayerOut {
    let layers = shell.layers;
    let full = shell.lod_layers >= f32(layers);
    let h = lod_height(layer, layers, shell.lod_layers);
    let n = normalize(v.normal);
    let u = normalize(v.tangent - n * dot(n, v.tangent));
    let w = cross(n, u);
    let root = v.position + shell.motion;
    let rest_tip = root + shell.shell_length * n;
    let tip = rest_tip + v.tip_offset;
    let coupling = shell.coupling;
    var offset = coupled_offset(coupling, shell.coupling_exponent, root, rest_tip, tip, h);
    var t = coupled_tangent(coupling, shell.coupling_exponent, root, rest_tip, tip, h);
    if CURL {
        let wet = wetness_at(v.uv).w;
        offset += curl_offset(h, wet, shell.curl_radius, shell.curl_frequency, u, w);
        t += curl_tangent(h, wet, shell.curl_radius, shell.curl_frequency, u, w);
    }
    // strand_tangent's fallback: with the tip at rest (p = p0) the
    // Bézier arrives at the tip with zero speed, so at h = 1 the
    // derivative vanishes; the strand then points along its rest direction.
    if dot(t, t) == 0.0 {
        t = rest_tip - root;
    }
    var out: LayerOut;
    out.world = root + offset;
    out.clip = shell.view_proj * vec4<f32>(out.world, 1.0);
    out.uv = v.uv;
    out.tangent = t;
    out.normal = n;
    out.u_axis = u;
    out.h = h;
    out.clump_profile = 0.0;
    if CLUMP {
        out.clump_profile = clump_profile(h, shell.clump_w, layers);
    }
    out.slice = f32(layer);
    out.fade = 1.0;
    out.coverage = 1.0;
    if !full {
        let last = f32(textureNumLayers(fur_layers) - 1);
        out.slice = clamp(h * f32(layers) - 1.0, 0.0, last);
        if layer == 0u {
            out.fade = shell.lod_layers - floor(shell.lod_layers - 1e-6);
        }
        out.coverage = f32(layers) / shell.lod_layers;
    }
    return out;
}

// The shell texture at a continuous slice: one lookup on a slice, two
// blended between slices.
fn fur_at(uv: vec2<f32>, slice: f32) -> vec4<f32> {
    let below = floor(slice);
    let a = textureSampleLevel(fur_layers, fur_sampler, uv, i32(below), shell.fur_mip);
    let s = slice - below;
    if s == 0.0 {
        return a;
    }
    let b = textureSampleLevel(fur_layers, fur_sampler, uv, i32(below) + 1, shell.fur_mip);
    return mix(a, b, s);
}

@fragment
fn fs_layer(v: LayerOut) -> @location(0) vec4<f32> {
    let h = v.h;
    var uv_color = v.uv;
    var uv_geo = v.uv * shell.tiles;
    // Alg. 2.
    if CLUMP {
        let here = wetness_at(v.uv);
        if here.w != 0.0 {
            let d = clump_displacement(v.clump_profile, shell.clump_strength, here.w, v.uv, here.xy);
            if distance(v.uv, here.xy) > here.z {
                discard;
            }
            if wetness_at(v.uv + d).w == 0.0 {
                discard;
            }
            uv_color += d;
            uv_geo += d * shell.tiles;
        }
    }
    let fur = fur_at(uv_geo, v.slice);
    if fur.a == 0.0 {
        discard;
    }
    var alpha = fur.a;
    if v.coverage != 1.0 {
        alpha = 1.0 - pow(1.0 - alpha, v.coverage);
    }
    alpha *= v.fade * shell.fur_opacity;
    let color = textureSampleLevel(color_texture, color_sampler, uv_color, 0.0).rgb;
    // The strand tangent, leaning with the texel's own hair: its direction
    // in the texture plane (x along dP/du, y down the image, i.e. −v).
    let n = normalize(v.normal);
    let u = normalize(v.u_axis);
    let lean = (2.0 * fur.r - 1.0) * u - (2.0 * fur.g - 1.0) * cross(n, u);
    let t = normalize(normalize(v.tangent) + lean);
    let e = normalize(shell.eye - v.world);
    return vec4<f32>(shade(color, fur.b, t, n, shell.light_dir, e, h), alpha);
}

// ---- the fins (Lengyel et al. 2001) ----

// Mirrors FinRecord in shells/fins.rs: the edge's two vertices.
@group(2) @binding(0) var<storage, read> fins: array<vec2<u32>>;
// PoseVertex, SurfaceVertex and TipOffset as storage: 9, 2 and 3 floats.
@group(2) @binding(1) var<storage, read> pose: array<f32>;
@group(2) @binding(2) var<storage, read> surface: array<vec2<f32>>;
@group(2) @binding(3) var<storage, read> tips: array<f32>;

fn pose_position(i: u32) -> vec3<f32> {
    return vec3<f32>(pose[9u * i], pose[9u * i + 1u], pose[9u * i + 2u]) + shell.motion;
}

fn pose_normal(i: u32) -> vec3<f32> {
    return normalize(vec3<f32>(pose[9u * i + 3u], pose[9u * i + 4u], pose[9u * i + 5u]));
}

fn tip_offset(i: u32) -> vec3<f32> {
    return vec3<f32>(tips[3u * i], tips[3u * i + 1u], tips[3u * i + 2u]);
}

struct FinOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) uv: vec2<f32>,
    // The strand's direction.
    @location(2) tangent: vec3<f32>,
    // Height up the fin, 0 at the skin.
    @location(3) h: f32,
    // Across the fin in texture units: a step between the parallel cuts.
    @location(4) @interpolate(flat) across: vec2<f32>,
    @location(5) @interpolate(flat) opacity: f32,
};

// How much of a fin shows (Lengyel et al. §4): fading in as the edge
// comes edge-on (|n · e| below fin_width, n the smooth normal of the
// edge's two vertices), and as the fin's own plane turns towards the eye
// (a fin seen edge-on would draw a line).
fn fin_visibility(n: vec3<f32>, along: vec3<f32>, e: vec3<f32>) -> f32 {
    let edge_on = 1.0 - smoothstep(0.0, shell.fin_width, abs(dot(n, e)));
    let plane = cross(along, n);
    if dot(plane, plane) == 0.0 {
        return 0.0;
    }
    let facing = smoothstep(0.3, 0.8, abs(dot(normalize(plane), e)));
    return edge_on * facing;
}

@vertex
fn vs_fin(@builtin(vertex_index) index: u32) -> FinOut {
    let fin = fins[index / 6u];
    // Two triangles: (a, b, b top), (a, b top, a top).
    let corner = index % 6u;
    let at_b = corner == 1u || corner == 2u || corner == 4u;
    let top = corner == 2u || corner == 4u || corner == 5u;
    let a = fin.x;
    let b = fin.y;
    var i = a;
    if at_b {
        i = b;
    }
    let middle = 0.5 * (pose_position(a) + pose_position(b));
    let e = normalize(shell.eye - middle);
    var edge_normal = pose_normal(a) + pose_normal(b);
    if dot(edge_normal, edge_normal) == 0.0 {
        edge_normal = pose_normal(a);
    }
    let edge = pose_position(b) - pose_position(a);
    let visible = fin_visibility(normalize(edge_normal), edge, e) * shell.fin_opacity;
    var out: FinOut;
    if visible <= 0.0 {
        // Outside the clip volume: the fin is not drawn.
        out.clip = vec4<f32>(2.0, 2.0, 2.0, 1.0);
        return out;
    }
    let root = pose_position(i);
    let n = pose_normal(i);
    let rest_tip = root + shell.shell_length * n;
    let tip = rest_tip + tip_offset(i);
    let coupling = shell.coupling;
    var h = 0.0;
    if top {
        h = 1.0;
    }
    out.world = root + coupled_offset(coupling, shell.coupling_exponent, root, rest_tip, tip, h);
    out.clip = shell.view_proj * vec4<f32>(out.world, 1.0);
    out.uv = surface[i];
    out.tangent = coupled_tangent(coupling, shell.coupling_exponent, root, rest_tip, tip, 0.5);
    out.h = h;
    let along = (surface[b] - surface[a]) * shell.tiles;
    let texel = 1.0 / f32(textureDimensions(fur_layers).x);
    var across = vec2<f32>(-along.y, along.x);
    if dot(across, across) > 0.0 {
        across = normalize(across) * 4.0 * texel;
    }
    out.across = across;
    out.opacity = visible;
    return out;
}

@fragment
fn fs_fin(v: FinOut) -> @location(0) vec4<f32> {
    // A fin shows the fur seen side-on: two parallel vertical cuts
    // through the blade volume, a few texels apart, over each other.
    let layers = textureNumLayers(fur_layers);
    let slice = clamp(v.h * f32(layers) - 1.0, 0.0, f32(layers - 1));
    let uv = v.uv * shell.tiles;
    let near = fur_at(uv, slice);
    let far = fur_at(uv + v.across, slice);
    let clear = (1.0 - near.a) * (1.0 - far.a);
    var fur = near;
    if far.a > near.a {
        fur = far;
    }
    let alpha = (1.0 - clear) * v.opacity * shell.fur_opacity;
    if alpha <= 0.0 {
        discard;
    }
    let color = textureSampleLevel(color_texture, color_sampler, v.uv, 0.0).rgb;
    let t = normalize(v.tangent);
    let e = normalize(shell.eye - v.world);
    return vec4<f32>(shade(color, fur.b, t, t, shell.light_dir, e, v.h), alpha);
}
