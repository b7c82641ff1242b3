// A groom's hairs grown again from this frame's guides and skin, one
// invocation a hair (pelage::groom::GroomRecipe has what each hair keeps;
// its module docs say why the split). Every function mirrors the Rust one
// named in its comment; keep them in step (tests/groom.rs grows both and
// compares hair by hair). Points are written point-major (point j of hair
// h at j * hairs + h) so neighbouring invocations write neighbouring
// memory.

const MAX_POINTS: u32 = 32u;
const MAX_WEIGHTS: u32 = 8u;
const TAU: f32 = 6.283185307179586;
// pelage::groom::ops::noise::VectorNoise::OFF_LATTICE.
const OFF_LATTICE: vec3<f32> = vec3<f32>(0.371, 0.713, 0.137);

// Mirrors GroomPassUniform in pelage-shaders' groom.rs (pelage-gpu's layout
// test checks names and offsets).
struct GroomPass {
    // The pass's first hair and how many.
    first: u32,
    count: u32,
    // Steps the pass's hairs go through.
    steps: u32,
    // Points a hair and a guide.
    points: u32,
    guide_points: u32,
    // Hairs in all: the stride of a point's row.
    hairs: u32,
    values_per_hair: u32,
    // 1: carry the hairs from the rest skin to the posed one.
    posed: u32,
    // Where the guide-to-hair resampling starts in `tables` (u32::MAX: none).
    resample_at: u32,
    // The render hairs' first (widths are theirs alone).
    render_first: u32,
    // Every width's factor (level of detail).
    width_scale: f32,
    // Where each section of `data` starts.
    weights_at: u32,
    normals_at: u32,
    values_at: u32,
    steps_at: u32,
    tables_at: u32,
    permutation_at: u32,
    widths_at: u32,
    // Bit 0: keep hairs out of the skin at rest after the operators;
    // bit 1: and out of this frame's posed skin after the carry.
    outside: u32,
    // The gap kept above the skin.
    gap: f32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
};

// pelage::groom::RecipeStep.
struct Step {
    kind: u32,
    values: u32,
    masked: u32,
    table: u32,
    permutation: u32,
    vectors: u32,
    centres: u32,
    pad0: u32,
};

// A hair's root: where it is and how it is carried.
struct HairRoot {
    // Rest position; w: the skin triangle (u32 bits).
    position: vec4<f32>,
    // Rest skin normal; w: the first barycentric.
    normal: vec4<f32>,
    // The rest skin frame's origin; w: the second barycentric.
    origin: vec4<f32>,
    // The rest skin frame's columns (tangent, bitangent, normal); x_axis.w:
    // 1 where the hair grows bare (a clump centre cut away: its
    // interpolated shape).
    x_axis: vec4<f32>,
    y_axis: vec4<f32>,
    z_axis: vec4<f32>,
};

@group(0) @binding(0) var<storage, read> hair_roots: array<HairRoot>;
// Everything else that does not change, one array of 32-bit words (floats
// by their bits: read as u32s, so no denormal is flushed on the way): each
// hair's guide weights, the guides' normals,
// each hair's values, the steps, their tables, the noise permutations and
// the render hairs' widths, where the pass says each starts. One binding
// keeps the shader within the storage buffers a default device allows.
@group(0) @binding(1) var<storage, read> data: array<u32>;
// This frame's guides: each point's offset from its guide's root, in rest space.
// (Written by `guides_to_rest` when the guides come from GPU strands.)
@group(0) @binding(2) var<storage, read_write> guide_offsets: array<vec4<f32>>;
// This frame's skin: a vertex's posed position, then its normal.
@group(0) @binding(3) var<storage, read> skin: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> triangles: array<u32>;
// xyz: the point; w: its width.
@group(0) @binding(5) var<storage, read_write> points: array<vec4<f32>>;
// The skin hairs are kept out of, at rest and in this frame's pose: each
// a grid as skin_sdf.wgsl reads it, in words (floats by their bits): a
// 12-word header, its nodes' distances, their nearest triangles (from the
// header's pad1), its triangles (six vec4s each, after the nodes).
@group(0) @binding(6) var<storage, read> rest_skin_sdf: array<u32>;
@group(0) @binding(7) var<storage, read> posed_skin_sdf: array<u32>;

// Word `i` of grid `g`'s buffer (its pad0: 0 at rest, 1 posed).
fn sdf_word(g: Grid, i: u32) -> u32 {
    if g.pad0 == 0u {
        return rest_skin_sdf[i];
    }
    return posed_skin_sdf[i];
}

// skin_sdf.wgsl's reads.
fn sdf_distance(g: Grid, i: u32) -> f32 {
    return bitcast<f32>(sdf_word(g, i));
}

fn sdf_nearest(g: Grid, i: u32) -> u32 {
    return sdf_word(g, g.pad1 + i - g.node_offset);
}

fn sdf_triangle(g: Grid, i: u32) -> vec3<f32> {
    let k = g.pad1 + g.nx * g.ny * g.nz + 4u * i;
    return bitcast<vec3<f32>>(vec3<u32>(sdf_word(g, k), sdf_word(g, k + 1u), sdf_word(g, k + 2u)));
}

// Grid `which`'s header (0: at rest, 1: posed).
fn grid_of(which: u32) -> Grid {
    var w: array<u32, 12>;
    for (var i = 0u; i < 12u; i++) {
        if which == 0u {
            w[i] = rest_skin_sdf[i];
        } else {
            w[i] = posed_skin_sdf[i];
        }
    }
    return Grid(
        bitcast<vec3<f32>>(vec3<u32>(w[0], w[1], w[2])), bitcast<f32>(w[3]),
        w[4], w[5], w[6], bitcast<f32>(w[7]),
        w[8], w[9], w[10], w[11],
    );
}

// pelage::dynamics::strands::follow_outside with a still groom's contact
// (OutsideSkin::apply): the point at `len` from `leader` toward `goal`,
// pushed out to `thickness` above the skin up to 8 times, keeping its
// length unless that takes it back in.
fn follow_outside(g: Grid, leader: vec3<f32>, goal: vec3<f32>, len: f32, fallback: vec3<f32>, thickness: f32) -> vec3<f32> {
    var q = leader + len * normalize_or(goal - leader, fallback);
    for (var k = 0u; k < 8u; k++) {
        let s = sample(g, q);
        if all(s.out == vec3<f32>(0.0)) || s.d >= thickness {
            break;
        }
        let pushed = q + (thickness - s.d) * s.out;
        q = leader + len * normalize_or(pushed - leader, s.out);
        if sample(g, q).d < 0.0 {
            q = pushed;
        }
    }
    return q;
}

// pelage::groom::OutsideSkin::apply: from the first point after the root
// that is not clear of the skin and nearer it than the gap, each point
// follows the one before at its length, out of the skin.
fn keep_out(g: Grid, n: u32, normal: vec3<f32>) {
    var first = 0u;
    for (var i = 1u; i < n; i++) {
        if !clear_of(g, pts[i], pass_.gap) && sample(g, pts[i]).d < pass_.gap {
            first = i;
            break;
        }
    }
    if first == 0u {
        return;
    }
    var before = pts[first - 1u];
    for (var i = first; i < n; i++) {
        let goal = pts[i];
        let len = length(goal - before);
        pts[i] = follow_outside(g, pts[i - 1u], goal, len, normal, pass_.gap);
        before = goal;
    }
}
@group(1) @binding(0) var<uniform> pass_: GroomPass;

// A hair's guide `i` of MAX_WEIGHTS: (guide as u32 bits, weight).
fn weight_at(i: u32) -> vec2<f32> {
    let k = pass_.weights_at + 2u * i;
    return vec2<f32>(bitcast<f32>(data[k]), bitcast<f32>(data[k + 1u]));
}

fn guide_normal(g: u32) -> vec3<f32> {
    let k = pass_.normals_at + 3u * g;
    return bitcast<vec3<f32>>(vec3<u32>(data[k], data[k + 1u], data[k + 2u]));
}

// Word `i` of the hairs' values (a hair's block, then its steps').
fn value_word(i: u32) -> f32 {
    return bitcast<f32>(data[pass_.values_at + i]);
}

// Word `i` of the steps' tables (profiles, resamplings).
fn table_word(i: u32) -> f32 {
    return bitcast<f32>(data[pass_.tables_at + i]);
}

fn hair_width(i: u32) -> f32 {
    return bitcast<f32>(data[pass_.widths_at + i]);
}

// pelage::groom::RecipeStep `s`, eight words.
fn step_at(s: u32) -> Step {
    let k = pass_.steps_at + 8u * s;
    var w: array<u32, 8>;
    for (var i = 0u; i < 8u; i++) {
        w[i] = data[k + i];
    }
    return Step(w[0], w[1], w[2], w[3], w[4], w[5], w[6], w[7]);
}

var<private> pts: array<vec3<f32>, MAX_POINTS>;
var<private> before: array<vec3<f32>, MAX_POINTS>;
var<private> tangents: array<vec3<f32>, MAX_POINTS>;
var<private> frame: array<vec3<f32>, MAX_POINTS>;
var<private> samples: array<vec3<f32>, MAX_POINTS>;
// The noise field the current step reads (noise.wgsl's perm_at).
var<private> perm_base: u32;

fn perm_at(i: u32) -> u32 {
    return data[pass_.permutation_at + perm_base + (i & 511u)];
}

// pelage::groom::ops::param.
fn param(j: u32, n: u32) -> f32 {
    if n > 1u {
        return f32(j) / f32(n - 1u);
    }
    return 0.0;
}

// glam's Vec3::any_orthonormal_vector (Duff et al. 2017); signum(0) = 1.
fn any_orthonormal(v: vec3<f32>) -> vec3<f32> {
    let s = select(-1.0, 1.0, v.z >= 0.0);
    let a = -1.0 / (s + v.z);
    let b = v.x * v.y * a;
    return vec3<f32>(b, s + v.y * v.y * a, -v.y);
}

// glam's normalize_or_zero.
fn normalize_or_zero(v: vec3<f32>) -> vec3<f32> {
    let len = length(v);
    if len > 0.0 && len < 3.0e38 {
        return v / len;
    }
    return vec3<f32>(0.0);
}

// glam's Mat3::from_quat (a unit quaternion, xyz then w).
fn mat3_from_quat(q: vec4<f32>) -> mat3x3<f32> {
    let x2 = q.x + q.x;
    let y2 = q.y + q.y;
    let z2 = q.z + q.z;
    let xx = q.x * x2;
    let xy = q.x * y2;
    let xz = q.x * z2;
    let yy = q.y * y2;
    let yz = q.y * z2;
    let zz = q.z * z2;
    let wx = q.w * x2;
    let wy = q.w * y2;
    let wz = q.w * z2;
    return mat3x3<f32>(
        vec3<f32>(1.0 - (yy + zz), xy + wz, xz - wy),
        vec3<f32>(xy - wz, 1.0 - (xx + zz), yz + wx),
        vec3<f32>(xz + wy, yz - wx, 1.0 - (xx + yy)),
    );
}

// glam's Quat::from_rotation_arc as a matrix: the shortest turn from `a`
// to `b` (unit vectors), a half turn about any perpendicular
// where they oppose to within two float epsilons.
fn rotation_arc(a: vec3<f32>, b: vec3<f32>) -> mat3x3<f32> {
    let one_minus_eps = 1.0 - 2.0 * 1.1920929e-7;
    let d = dot(a, b);
    if d > one_minus_eps {
        return mat3x3<f32>(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, 0.0, 1.0));
    }
    if d < -one_minus_eps {
        // from_axis_angle(axis, π): sin(π/2) = 1, cos(π/2) in f32.
        return mat3_from_quat(vec4<f32>(any_orthonormal(a), -4.371139e-8));
    }
    let c = cross(a, b);
    let q = vec4<f32>(c, 1.0 + d);
    return mat3_from_quat(q * (1.0 / length(q)));
}

// pelage::interp::rotation_between (from `a_dir` to `b_dir`): Rodrigues
// without trigonometry; glam's rotation arc where the normals nearly
// oppose (1 + cos < 1e-4), as the CPU does.
fn rotation_between(a_dir: vec3<f32>, b_dir: vec3<f32>) -> mat3x3<f32> {
    let v = cross(a_dir, b_dir);
    let c = dot(a_dir, b_dir);
    let one_plus_c = 1.0 + c;
    if one_plus_c < 1e-4 {
        return rotation_arc(a_dir, b_dir);
    }
    let h = 1.0 / one_plus_c;
    let hx = h * v.x;
    let hy = h * v.y;
    let hz = h * v.z;
    let xy = hx * v.y;
    let xz = hx * v.z;
    let yz = hy * v.z;
    return mat3x3<f32>(
        vec3<f32>(1.0 - hy * v.y - hz * v.z, xy + v.z, xz - v.y),
        vec3<f32>(xy - v.z, 1.0 - hx * v.x - hz * v.z, yz + v.x),
        vec3<f32>(xz + v.y, yz - v.x, 1.0 - hx * v.x - hy * v.y),
    );
}

// pelage::interp::Interpolator::shape, then Resampling::apply: the
// guides' offsets turned into the hair's frame, weighted, at the hair's
// point count.
fn interpolate(h: u32, position: vec3<f32>, normal: vec3<f32>) {
    let gp = pass_.guide_points;
    for (var j = 0u; j < gp; j++) {
        samples[j] = position;
    }
    for (var w = 0u; w < MAX_WEIGHTS; w++) {
        let gw = weight_at(h * MAX_WEIGHTS + w);
        if gw.y == 0.0 {
            continue;
        }
        let g = bitcast<u32>(gw.x);
        let turn = gw.y * rotation_between(guide_normal(g), normal);
        for (var j = 0u; j < gp; j++) {
            samples[j] += turn * guide_offsets[g * gp + j].xyz;
        }
    }
    let n = pass_.points;
    if pass_.resample_at == 0xffffffffu {
        for (var j = 0u; j < n; j++) {
            pts[j] = samples[j];
        }
    } else {
        for (var k = 0u; k < n; k++) {
            let at = pass_.resample_at + 2u * k;
            let j = u32(table_word(at));
            pts[k] = mix(samples[j], samples[j + 1u], table_word(at + 1u));
        }
    }
}

// pelage::curves::frames::catmull_rom_tangents and
// rotation_minimizing_normals from the skin normal's any_orthonormal_vector
// (Scratch::frame_along).
fn frame_along(n: u32, skin_normal: vec3<f32>) {
    if n < 2u {
        for (var i = 0u; i < n; i++) {
            tangents[i] = vec3<f32>(0.0, 0.0, 1.0);
        }
    } else {
        for (var i = 0u; i < n; i++) {
            let a = pts[select(i - 1u, 0u, i == 0u)];
            let b = pts[min(i + 1u, n - 1u)];
            tangents[i] = normalize_or_zero(b - a);
        }
        for (var i = 1u; i < n; i++) {
            if all(tangents[i] == vec3<f32>(0.0)) {
                tangents[i] = tangents[i - 1u];
            }
        }
        for (var k = 1u; k < n; k++) {
            let i = n - 1u - k;
            if all(tangents[i] == vec3<f32>(0.0)) {
                tangents[i] = tangents[i + 1u];
            }
        }
    }
    if n == 0u {
        return;
    }
    let first = any_orthonormal(skin_normal);
    let t0 = tangents[0];
    var r = normalize_or_zero(first - t0 * dot(t0, first));
    if all(r == vec3<f32>(0.0)) {
        r = any_orthonormal(t0);
    }
    frame[0] = r;
    for (var i = 0u; i + 1u < n; i++) {
        let v1 = pts[i + 1u] - pts[i];
        let c1 = dot(v1, v1);
        let k1 = select(0.0, 2.0 / c1, c1 > 1e-20);
        let t_l = tangents[i] - k1 * dot(v1, tangents[i]) * v1;
        let v2 = tangents[i + 1u] - t_l;
        let c2 = dot(v2, v2);
        let k2 = select(0.0, 2.0 / c2, c2 > 1e-20);
        let r_l = r - k1 * dot(v1, r) * v1;
        let reflected = r_l - k2 * dot(v2, r_l) * v2;
        let t = tangents[i + 1u];
        let projected = reflected - t * dot(t, reflected);
        if dot(projected, projected) > 1e-12 {
            r = reflected;
        } else {
            r = any_orthonormal(t);
        }
        frame[i + 1u] = r;
    }
}

// pelage::groom::ops::Length::lengthen.
fn lengthen(n: u32, factor: f32) {
    let origin = pts[0];
    for (var j = 1u; j < n; j++) {
        pts[j] = origin + (pts[j] - origin) * factor;
    }
}

// pelage::groom::ops::Curl::apply_to_hair.
fn curl(n: u32, v: u32, table: u32, skin_normal: vec3<f32>) {
    let radius = value_word(v);
    if radius == 0.0 {
        return;
    }
    let turns = value_word(v + 1u);
    let phase = value_word(v + 2u);
    frame_along(n, skin_normal);
    for (var j = 0u; j < n; j++) {
        let t = param(j, n);
        let alpha = radius * table_word(table + j);
        let angle = TAU * turns * t + phase;
        let r = frame[j];
        let b = cross(tangents[j], r);
        pts[j] += alpha * (cos(angle) * r + sin(angle) * b);
    }
}

// pelage::groom::ops::Twist::apply_to_hair: each point turned about the
// root–tip axis (Rodrigues' rotation for glam's quaternion).
fn twist(n: u32, v: u32, table: u32) {
    let angle = value_word(v);
    let origin = pts[0];
    let axis = normalize_or_zero(pts[n - 1u] - origin);
    if angle == 0.0 || all(axis == vec3<f32>(0.0)) {
        return;
    }
    for (var j = 1u; j < n; j++) {
        let theta = angle * table_word(table + j);
        let d = pts[j] - origin;
        let c = cos(theta);
        let s = sin(theta);
        pts[j] = origin + d * c + cross(axis, d) * s + axis * dot(axis, d) * (1.0 - c);
    }
}

// pelage::groom::ops::Noise::displace_each: the field at the hair's
// points (or at `vectors` points along it, spread back to every point).
fn noise(n: u32, v: u32, step: Step) {
    let amplitude = value_word(v);
    if amplitude == 0.0 || n == 0u {
        return;
    }
    let frequency = value_word(v + 1u);
    let m = step.vectors;
    if m == n {
        for (var j = 0u; j < n; j++) {
            let s = perlin3_vector(pts[j] * frequency + OFF_LATTICE);
            let a = amplitude * table_word(step.table + j);
            if a != 0.0 {
                pts[j] += a * s;
            }
        }
        return;
    }
    let to_vectors = step.table + n;
    for (var k = 0u; k < m; k++) {
        let j = u32(table_word(to_vectors + 2u * k));
        let f = table_word(to_vectors + 2u * k + 1u);
        samples[k] = perlin3_vector(mix(pts[j], pts[j + 1u], f) * frequency + OFF_LATTICE);
    }
    let to_points = to_vectors + 2u * m;
    for (var j = 0u; j < n; j++) {
        let a = amplitude * table_word(step.table + j);
        if a != 0.0 {
            let k = u32(table_word(to_points + 2u * j));
            let f = table_word(to_points + 2u * j + 1u);
            pts[j] += a * mix(samples[k], samples[k + 1u], f);
        }
    }
}

// pelage::groom::ops::Frizz::apply_to_hair.
fn frizz(n: u32, v: u32, table: u32) {
    let amplitude = value_word(v);
    if amplitude == 0.0 {
        return;
    }
    let frequency = value_word(v + 1u);
    let phase = vec3<f32>(value_word(v + 2u), value_word(v + 3u), value_word(v + 4u));
    for (var j = 0u; j < n; j++) {
        let t = param(j, n);
        let at = phase + vec3<f32>(frequency * t, 0.0, 0.0);
        pts[j] += amplitude * table_word(table + j) * perlin3_vector(at + OFF_LATTICE);
    }
}

// pelage::groom::ops::Flyaways::apply_to_hair.
fn flyaways(n: u32, v: u32, table: u32) {
    if value_word(v) == 0.0 {
        return;
    }
    let len = value_word(v + 1u);
    let spread = value_word(v + 2u);
    let frequency = value_word(v + 3u);
    let phase = vec3<f32>(value_word(v + 4u), value_word(v + 5u), value_word(v + 6u));
    let across = vec3<f32>(value_word(v + 7u), value_word(v + 8u), value_word(v + 9u));
    let origin = pts[0];
    for (var j = 0u; j < n; j++) {
        let t = param(j, n);
        let at = phase + vec3<f32>(frequency * t, 0.0, 0.0);
        let wander = perlin3_vector(at + OFF_LATTICE);
        pts[j] = origin + (pts[j] - origin) * len + spread * table_word(table + j) * (across + 0.5 * wander);
    }
}

// pelage::groom::ops::Cut::cut_at: the hair ends at curve parameter `at`
// and keeps its point count (point k at parameter at · t_k of the old one).
fn cut(n: u32, v: u32) {
    let at = value_word(v);
    if at >= 1.0 || n < 2u {
        return;
    }
    for (var j = 0u; j < n; j++) {
        before[j] = pts[j];
    }
    for (var k = 0u; k < n; k++) {
        let x = at * param(k, n) * f32(n - 1u);
        let j = min(u32(x), n - 2u);
        let f = x - f32(j);
        pts[k] = before[j] + (before[j + 1u] - before[j]) * f;
    }
}

// pelage::groom::ops::Strands::split, for the one strand hair this is:
// offset around its base hair in the base's rotation-minimizing frame,
// spread from the root's to the tip's, turning by the twist.
fn strand(n: u32, v: u32, skin_normal: vec3<f32>) {
    let s0 = value_word(v);
    let s1 = value_word(v + 1u);
    let twist = value_word(v + 2u);
    let rho = value_word(v + 3u);
    let turn = value_word(v + 4u);
    frame_along(n, skin_normal);
    for (var j = 0u; j < n; j++) {
        let t = param(j, n);
        let angle = TAU * (turn + twist * t);
        let r = frame[j];
        let side = cross(tangents[j], r);
        pts[j] += (s0 + t * (s1 - s0)) * rho * (cos(angle) * r + sin(angle) * side);
    }
}

// pelage::groom::ops::Clump::pull: toward the centre hair's points, grown
// by an earlier pass.
fn clump(n: u32, v: u32, step: Step) {
    let w = value_word(v + 1u);
    if w == 0.0 {
        return;
    }
    let centre = step.centres + bitcast<u32>(value_word(v));
    for (var j = 0u; j < n; j++) {
        let c = points[j * pass_.hairs + centre].xyz;
        pts[j] += w * table_word(step.table + j) * (c - pts[j]);
    }
}

// pelage::anim::SkinPose::frame_at on this frame's skin: the root's
// position and frame (tangent along the longest edge, normal from the
// vertex normals).
fn posed_frame(tri: u32, b1: f32, b2: f32) -> mat4x3<f32> {
    let a = triangles[3u * tri];
    let b = triangles[3u * tri + 1u];
    let c = triangles[3u * tri + 2u];
    let p0 = skin[2u * a].xyz;
    let p1 = skin[2u * b].xyz;
    let p2 = skin[2u * c].xyz;
    let position = p0 + b1 * (p1 - p0) + b2 * (p2 - p0);
    let w0 = 1.0 - b1 - b2;
    var normal = normalize_or_zero(w0 * skin[2u * a + 1u].xyz + b1 * skin[2u * b + 1u].xyz + b2 * skin[2u * c + 1u].xyz);
    if all(normal == vec3<f32>(0.0)) {
        normal = normalize_or_zero(cross(p1 - p0, p2 - p0));
        if all(normal == vec3<f32>(0.0)) {
            normal = vec3<f32>(0.0, 0.0, 1.0);
        }
    }
    // Rust's max_by keeps the last of equal lengths.
    var edge = p1 - p0;
    let e1 = p2 - p1;
    let e2 = p0 - p2;
    if dot(e1, e1) >= dot(edge, edge) {
        edge = e1;
    }
    if dot(e2, e2) >= dot(edge, edge) {
        edge = e2;
    }
    var tangent = normalize_or_zero(edge - normal * dot(normal, edge));
    if all(tangent == vec3<f32>(0.0)) {
        tangent = any_orthonormal(normal);
    }
    return mat4x3<f32>(tangent, cross(normal, tangent), normal, position);
}

@compute @workgroup_size(64)
fn grow_hairs(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = id.x + id.y * groups.x * 64u;
    if i >= pass_.count {
        return;
    }
    let h = pass_.first + i;
    let n = pass_.points;
    let root = hair_roots[h];
    let skin_normal = root.normal.xyz;
    interpolate(h, root.position.xyz, skin_normal);
    let bare = root.x_axis.w != 0.0;
    var steps = pass_.steps;
    if bare {
        steps = 0u;
    }
    for (var s = 0u; s < steps; s++) {
        let step = step_at(s);
        var v = h * pass_.values_per_hair + step.values;
        var m = 1.0;
        if step.masked != 0u {
            m = value_word(v);
            v += 1u;
            if m == 0.0 {
                continue;
            }
            for (var j = 0u; j < n; j++) {
                before[j] = pts[j];
            }
        }
        perm_base = step.permutation;
        switch step.kind {
            case 0u: { lengthen(n, value_word(v)); }
            case 1u: { curl(n, v, step.table, skin_normal); }
            case 2u: { twist(n, v, step.table); }
            case 3u: { noise(n, v, step); }
            case 4u: { frizz(n, v, step.table); }
            case 5u: { flyaways(n, v, step.table); }
            case 6u: { clump(n, v, step); }
            case 7u: { cut(n, v); }
            case 8u: { strand(n, v, skin_normal); }
            default: {}
        }
        if m != 1.0 {
            for (var j = 0u; j < n; j++) {
                pts[j] = before[j] + m * (pts[j] - before[j]);
            }
        }
    }
    if (pass_.outside & 1u) != 0u && !bare {
        keep_out(grid_of(0u), n, skin_normal);
    }
    if pass_.posed != 0u {
        let rest = mat3x3<f32>(root.x_axis.xyz, root.y_axis.xyz, root.z_axis.xyz);
        let posed = posed_frame(bitcast<u32>(root.position.w), root.normal.w, root.origin.w);
        let turn = mat3x3<f32>(posed[0], posed[1], posed[2]) * transpose(rest);
        for (var j = 0u; j < n; j++) {
            pts[j] = posed[3] + turn * (pts[j] - root.origin.xyz);
        }
        if (pass_.outside & 2u) != 0u {
            keep_out(grid_of(1u), n, posed[2]);
        }
    }
    var width_at = 0xffffffffu;
    if h >= pass_.render_first {
        width_at = (h - pass_.render_first) * n;
    }
    for (var j = 0u; j < n; j++) {
        var w = 0.0;
        if width_at != 0xffffffffu {
            w = hair_width(width_at + j) * pass_.width_scale;
        }
        points[j * pass_.hairs + h] = vec4<f32>(pts[j], w);
    }
}

// ---- the frame's guides from the GPU strands, without a read-back ----

// The strands as stepped (point i of strand s at i * strands + s).
@group(2) @binding(0) var<storage, read> strand_points: array<vec4<f32>>;
// Each guide's root: (triangle bits, b1, b2, 0), then its rest frame's
// columns (tangent, bitangent, normal): four vec4 a guide.
@group(2) @binding(1) var<storage, read> guide_roots: array<vec4<f32>>;

// pelage::anim::SkinBinding::to_rest for a whole guide, as offsets from
// its root: each point turned by the root's change of frame from this
// pose back to rest (`pass_.count` guides, `pass_.hairs` strands).
@compute @workgroup_size(64)
fn guides_to_rest(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let g = id.x + id.y * groups.x * 64u;
    if g >= pass_.count {
        return;
    }
    let root = guide_roots[4u * g];
    let posed = posed_frame(bitcast<u32>(root.x), root.y, root.z);
    let rest = mat3x3<f32>(guide_roots[4u * g + 1u].xyz, guide_roots[4u * g + 2u].xyz, guide_roots[4u * g + 3u].xyz);
    let turn = rest * transpose(mat3x3<f32>(posed[0], posed[1], posed[2]));
    let gp = pass_.guide_points;
    let strands = pass_.hairs;
    let first = strand_points[g].xyz;
    for (var i = 0u; i < gp; i++) {
        let p = strand_points[i * strands + g].xyz;
        guide_offsets[g * gp + i] = vec4<f32>(turn * (p - first), 0.0);
    }
}
