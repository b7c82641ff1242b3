// Real-time strands' math, without bindings: the ribbons a hair's points
// are drawn as, and the hair model they are shaded with. pelage-gpu puts
// it before hair.wgsl; Bevy imports it as `pelage::hair_math`.
//
// Ribbons: two triangles a segment, six vertices, pulled by vertex index
// from a points buffer (no vertex buffers), turned to face the camera,
// at least a pixel wide with their coverage scaled down where thinner
// (alpha-to-coverage with MSAA): thin hairs thin out instead of
// shimmering.
//
// Shading, a real-time hair model: Kajiya & Kay's (1989) diffuse for the
// light scattered many times, and Marschner et al.'s (2003) three lobes
// as games approximate them (Scheuermann 2004; Unreal's hair shading):
// each a Gaussian in the half angle θh = (θi + θo)/2 between the light's
// and the eye's inclinations to the hair, about a shift α, times an
// azimuthal factor in φ, the angle between them around the hair:
// - R, reflected at the surface: white, about α, strongest facing the
//   light (cos(φ/2));
// - TRT, reflected inside: the hair's colour, about −3α/2, twice as wide;
// - TT, transmitted: the hair's colour, about −α/2, half as wide, strongest
//   straight through (φ = π): the bright rim of a back-lit coat.

// Which ribbon vertex `vertex` is: its render hair, its segment's first
// point `j`, where along the segment (t: 0 or 1) and which side (±1).
struct RibbonCorner {
    hair: u32,
    j: u32,
    t: f32,
    side: f32,
};

// Vertex `vertex` of the ribbons of hairs of `points` points each.
fn ribbon_corner(vertex: u32, points: u32) -> RibbonCorner {
    // Two triangles over (t, side): (0,−1) (1,−1) (0,1) / (0,1) (1,−1) (1,1).
    var ts = array<f32, 6>(0.0, 1.0, 0.0, 0.0, 1.0, 1.0);
    var sides = array<f32, 6>(-1.0, -1.0, 1.0, 1.0, -1.0, 1.0);
    let segments = max(points, 2u) - 1u;
    let segment = vertex / 6u;
    let k = vertex % 6u;
    var c: RibbonCorner;
    c.hair = segment / segments;
    c.j = segment % segments;
    c.t = ts[k];
    c.side = sides[k];
    return c;
}

// The ribbon's corner in clip space, for a segment from `a` to `b` (xyz
// and width in w): across the segment on screen, at least a pixel wide;
// `px_per_unit` turns a width at `clip.w` into pixels, `half_size` is half
// the target's size in pixels.
fn ribbon_clip(a: vec4<f32>, b: vec4<f32>, t: f32, side: f32, view_proj: mat4x4<f32>, half_size: vec2<f32>, px_per_unit: f32) -> vec4<f32> {
    let p = mix(a.xyz, b.xyz, t);
    let width = mix(a.w, b.w, t);
    let ca = view_proj * vec4<f32>(a.xyz, 1.0);
    let cb = view_proj * vec4<f32>(b.xyz, 1.0);
    let clip = view_proj * vec4<f32>(p, 1.0);
    var direction = cb.xy / cb.w * half_size - ca.xy / ca.w * half_size;
    if length(direction) < 1e-6 {
        direction = vec2<f32>(1.0, 0.0);
    }
    let across = normalize(vec2<f32>(-direction.y, direction.x));
    let width_px = width * px_per_unit / clip.w;
    let offset_px = across * side * 0.5 * max(width_px, 1.0);
    return vec4<f32>(clip.xy + offset_px / half_size * clip.w, clip.zw);
}

// The drawn width's share of the true width: a ribbon `width` wide at
// `clip_w` is drawn at least a pixel wide.
fn ribbon_coverage(width: f32, px_per_unit: f32, clip_w: f32) -> f32 {
    return clamp(width * px_per_unit / clip_w, 0.0, 1.0);
}

// The hair model's numbers (from `[look]`: StrandLook).
struct HairLobes {
    // R's strength.
    specular: f32,
    // The highlights' longitudinal shift (Marschner's α_R, radians,
    // negative: toward the root) and width (β_R).
    shift: f32,
    roughness: f32,
    // TRT's strength.
    trt: f32,
    // TT's strength and its azimuthal lobe's exponent.
    transmission: f32,
    transmission_exponent: f32,
};

// An unnormalised Gaussian lobe: 1 at x = 0, width `beta`.
fn lobe(x: f32, beta: f32) -> f32 {
    return exp(-x * x / (2.0 * beta * beta));
}

// The light a hair of colour `base` along unit `t` sends towards the eye
// (unit `to_eye`) from a light of unit radiance in unit direction `l`:
// Kajiya-Kay's diffuse (wrapped, so light grazing the far side still
// reaches it) plus the R, TRT and TT lobes.
fn hair_radiance(t: vec3<f32>, l: vec3<f32>, to_eye: vec3<f32>, base: vec3<f32>, lobes: HairLobes) -> vec3<f32> {
    // Inclinations to the hair's normal plane, and the azimuth between
    // the light and the eye around the hair.
    let sin_i = clamp(dot(t, l), -1.0, 1.0);
    let sin_o = clamp(dot(t, to_eye), -1.0, 1.0);
    let theta_h = 0.5 * (asin(sin_i) + asin(sin_o));
    let across_l = l - t * sin_i;
    let across_v = to_eye - t * sin_o;
    let cos_phi = dot(across_l, across_v) / max(length(across_l) * length(across_v), 1e-6);
    let beta = max(lobes.roughness, 0.05);
    let alpha = lobes.shift;
    let r = lobes.specular * lobe(theta_h - alpha, beta) * sqrt(max(0.0, 0.5 + 0.5 * cos_phi));
    let trt = lobes.trt * lobe(theta_h + 1.5 * alpha, 2.0 * beta);
    let tt = lobes.transmission * lobe(theta_h + 0.5 * alpha, 0.5 * beta)
        * pow(max(0.0, -cos_phi), lobes.transmission_exponent);
    let cos_across = dot(normalize(across_v), l);
    let diffuse = sqrt(max(0.0, 1.0 - sin_i * sin_i)) * clamp(0.5 + 0.5 * cos_across, 0.0, 1.0);
    return base * 0.6 * diffuse + vec3<f32>(r) + base * (trt + tt);
}
