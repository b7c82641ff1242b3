// The shell-fur math every GPU host shares (pelage-gpu on wgpu, the Bevy
// plugin on Bevy's renderer): pure functions, no bindings, each mirroring
// the function of pelage::shell::math named the same (Silva et al. Eq. 1,
// Banisch & Wüthrich's couplings, curl Eq. 4, clumps Eq. 5 and Alg. 2,
// Kajiya-Kay Eq. 6). A host puts it before its own shader (pelage-gpu) or
// imports it as the module `pelage::shell_math` (Bevy's shader composer);
// keep it free of bindings and `#import`s so both can.

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

// Kajiya-Kay (Silva Eq. 6) with the shadow term: diffuse sin(t, l),
// specular (t·l t·e + sin(t, l) sin(t, e))^p, darkened towards the skin.
fn kajiya_kay_lit(color: vec3<f32>, t: vec3<f32>, l: vec3<f32>, e: vec3<f32>, h: f32, specular: vec3<f32>, exponent: f32, k_shadow: f32) -> vec3<f32> {
    let sin_tl = length(cross(t, l));
    let sin_te = length(cross(t, e));
    let diffuse = color * sin_tl;
    let base = max(dot(t, l) * dot(t, e) + sin_tl * sin_te, 0.0);
    return shadow_factor(h, k_shadow) * (diffuse + specular * pow(base, exponent));
}
