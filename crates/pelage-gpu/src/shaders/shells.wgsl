// Shell fur (Silva et al., Lengyel et al., Banisch & Wüthrich): the skin
// drawn once with depth write, then all N layers in one instanced draw
// (instance n = layer n), depth test on and write off, blended in layer
// order. Every formula mirrors a function of pelage::shell::math, named
// the same; keep them in step (tests/shells.rs renders against the Rust).

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
    pad0: vec2<f32>,
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

// Mirrors ShellVertex (locations 0-3) and TipOffset (4) in shells/mod.rs
// (a test checks names and locations).
struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    // Mask (image) coordinates: (u, 1 − v).
    @location(2) uv: vec2<f32>,
    // dP/du, the texture's x direction on the surface.
    @location(3) tangent: vec3<f32>,
    // p − p0: how far the strand's tip particle has moved (0 at rest).
    @location(4) tip_offset: vec3<f32>,
};

// ---- pelage::shell::math ----

fn layer_height(n: u32, layers: u32) -> f32 {
    return f32(1u + n) / f32(max(layers, 1u));
}

// Strand::point − root: β(h).
fn bend_offset(root: vec3<f32>, rest_tip: vec3<f32>, tip: vec3<f32>, h: f32) -> vec3<f32> {
    let a = 1.0 - h;
    return a * a * root + 2.0 * a * h * rest_tip + h * h * tip - root;
}

fn bend_tangent(root: vec3<f32>, rest_tip: vec3<f32>, tip: vec3<f32>, h: f32) -> vec3<f32> {
    return 2.0 * (1.0 - h) * (rest_tip - root) + 2.0 * h * (tip - rest_tip);
}

// Strand::direction's s: the unit stick direction, or the rest direction.
fn stick_direction(root: vec3<f32>, rest_tip: vec3<f32>, tip: vec3<f32>) -> vec3<f32> {
    let d = tip - root;
    if dot(d, d) > 0.0 {
        return normalize(d);
    }
    return normalize(rest_tip - root);
}

// Strand::coupled_offset.
fn coupled_offset(mode: u32, k: f32, root: vec3<f32>, rest_tip: vec3<f32>, tip: vec3<f32>, h: f32) -> vec3<f32> {
    if mode == 0u {
        return bend_offset(root, rest_tip, tip, h);
    }
    let s = stick_direction(root, rest_tip, tip);
    let length = distance(rest_tip, root);
    if mode == 1u {
        return h * length * s;
    }
    let n = normalize(rest_tip - root);
    return length * (h * n + pow(h, k) * (s - n));
}

// Strand::coupled_tangent.
fn coupled_tangent(mode: u32, k: f32, root: vec3<f32>, rest_tip: vec3<f32>, tip: vec3<f32>, h: f32) -> vec3<f32> {
    if mode == 0u {
        return bend_tangent(root, rest_tip, tip, h);
    }
    let s = stick_direction(root, rest_tip, tip);
    let length = distance(rest_tip, root);
    if mode == 1u {
        return length * s;
    }
    let n = normalize(rest_tip - root);
    var slope = 0.0;
    if h > 0.0 {
        slope = k * pow(h, k - 1.0);
    }
    return length * (n + slope * (s - n));
}

fn curl_radius(h: f32, wet: f32, k_alpha: f32) -> f32 {
    return (1.0 - wet) * k_alpha * h;
}

fn curl_offset(h: f32, wet: f32, k_alpha: f32, omega: f32, u: vec3<f32>, v: vec3<f32>) -> vec3<f32> {
    let alpha = curl_radius(h, wet, k_alpha);
    let angle = omega * h;
    return alpha * cos(angle) * u + alpha * sin(angle) * v;
}

fn curl_tangent(h: f32, wet: f32, k_alpha: f32, omega: f32, u: vec3<f32>, v: vec3<f32>) -> vec3<f32> {
    let alpha = curl_radius(h, wet, k_alpha);
    let slope = (1.0 - wet) * k_alpha;
    let angle = omega * h;
    let s = sin(angle);
    let c = cos(angle);
    return slope * (c * u + s * v) + alpha * omega * (-s * u + c * v);
}

fn clump_profile(h: f32, w: f32, layers: u32) -> f32 {
    let k = log(f32(max(layers, 2u)));
    return max((1.0 - w) * h + w * (1.0 + log(max(h, 1e-6)) / k), 0.0);
}

// clump_displacement, with clump_profile(h, w, layers) given: it is the
// same for a whole layer, so the vertex shader works it out (two
// logarithms) and hands it to every fragment of the layer.
fn clump_displacement(profile: f32, strength: f32, wet: f32, pixel: vec2<f32>, centre: vec2<f32>) -> vec2<f32> {
    return profile * wet * strength * (pixel - centre);
}

fn shadow_factor(h: f32, k_shadow: f32) -> f32 {
    let k = max(k_shadow, 1.0);
    return (k - 1.0 + h) / k;
}

fn kajiya_kay(color: vec3<f32>, t: vec3<f32>, l: vec3<f32>, e: vec3<f32>, h: f32) -> vec3<f32> {
    let sin_tl = length(cross(t, l));
    let sin_te = length(cross(t, e));
    let diffuse = color * sin_tl;
    let base = max(dot(t, l) * dot(t, e) + sin_tl * sin_te, 0.0);
    let specular = shell.specular * pow(base, shell.specular_exponent);
    return shadow_factor(h, shell.k_shadow) * (diffuse + specular);
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
    @location(5) @interpolate(flat) layer: u32,
    // clump_profile(h, w, N) of this layer.
    @location(6) @interpolate(flat) clump_profile: f32,
};

@vertex
fn vs_layer(v: VertexIn, @builtin(instance_index) layer: u32) -> LayerOut {
    let layers = shell.layers;
    let h = layer_height(layer, layers);
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
    out.layer = layer;
    out.clump_profile = 0.0;
    if CLUMP {
        out.clump_profile = clump_profile(h, shell.clump_w, layers);
    }
    return out;
}

@fragment
fn fs_layer(v: LayerOut) -> @location(0) vec4<f32> {
    let layers = shell.layers;
    let h = layer_height(v.layer, layers);
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
    let fur = textureSampleLevel(fur_layers, fur_sampler, uv_geo, v.layer, 0.0);
    if fur.a == 0.0 {
        discard;
    }
    let color = textureSampleLevel(color_texture, color_sampler, uv_color, 0.0).rgb;
    // The strand tangent, leaning with the texel's own hair: its direction
    // in the texture plane (x along dP/du, y down the image, i.e. −v).
    let n = normalize(v.normal);
    let u = normalize(v.u_axis);
    let lean = (2.0 * fur.r - 1.0) * u - (2.0 * fur.g - 1.0) * cross(n, u);
    let t = normalize(normalize(v.tangent) + lean);
    let e = normalize(shell.eye - v.world);
    return vec4<f32>(shade(color, fur.b, t, n, shell.light_dir, e, h), fur.a);
}
