// A frame of guide strands (pelage::dynamics::strands: Dynamic
// Follow-The-Leader with bending, follow, wind, collisions with the
// skin's distance grid and friction), one invocation a strand, every
// substep of the frame in one dispatch. Every function mirrors the Rust
// one named the same; keep them in step (tests/strands.rs steps both and
// compares). Points are stored point-major (point i of strand s at
// i * strands + s) so neighbouring invocations read neighbouring memory.

// Mirrors StrandStepUniform in strands.rs (a test checks names and offsets).
struct StrandStep {
    // Gravity × the substep.
    gravity_h: vec3<f32>,
    // The substep.
    h: f32,
    // e^(−damping·h).
    decay: f32,
    // min(1, drag·h).
    drag: f32,
    // Per-iteration follow and bend fractions.
    follow: f32,
    bend: f32,
    ftl: f32,
    thickness: f32,
    friction: f32,
    turbulence: f32,
    turbulence_scale: f32,
    iterations: u32,
    substeps: u32,
    strands: u32,
    points: u32,
    // 0: no collisions; 1: one grid for every substep; else one a substep.
    grids: u32,
    pad0: u32,
    pad1: u32,
};


@group(0) @binding(0) var<uniform> step: StrandStep;
@group(0) @binding(1) var<storage, read_write> positions: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> velocities: array<vec4<f32>>;
// xyz: the point in its root's rest frame; w: its rest length.
@group(0) @binding(3) var<storage, read> rest: array<vec4<f32>>;
// Six a strand: position, tangent, normal where the frame starts, then
// where it ends.
@group(0) @binding(4) var<storage, read> roots: array<vec4<f32>>;
// Two a substep: the wind's gusting mean and the turbulence's drift.
@group(0) @binding(5) var<storage, read> winds: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read> permutation: array<u32>;

// noise.wgsl's table lookup: this shader's one field.
fn perm_at(i: u32) -> u32 {
    return permutation[i & 511u];
}
@group(0) @binding(7) var<storage, read> grids: array<Grid>;
@group(0) @binding(8) var<storage, read> distances: array<f32>;
@group(0) @binding(9) var<storage, read> nearest: array<u32>;
// Six a triangle: its corners, then its corners' normals.
@group(0) @binding(10) var<storage, read> triangles: array<vec4<f32>>;

const MAX_POINTS: u32 = 32u;
const COLLISION_PASSES: u32 = 3u;
const CONTACT: f32 = 1.05;
const KEEP_LENGTH_WITHIN: f32 = 0.9;

// skin_sdf.wgsl's reads: this shader's own buffers.
fn sdf_distance(g: Grid, i: u32) -> f32 {
    return distances[i];
}

fn sdf_nearest(g: Grid, i: u32) -> u32 {
    return nearest[i];
}

fn sdf_triangle(g: Grid, i: u32) -> vec3<f32> {
    return triangles[i].xyz;
}

fn normalize_or_zero(v: vec3<f32>) -> vec3<f32> {
    return normalize_or(v, vec3<f32>(0.0));
}

// ---- pelage::dynamics::strands ----

fn at(i: u32, s: u32) -> u32 {
    return i * step.strands + s;
}

// WindNow::at for substep k.
fn wind_at(k: u32, p: vec3<f32>) -> vec3<f32> {
    let mean = winds[2u * k].xyz;
    if step.turbulence == 0.0 {
        return mean;
    }
    let drift = winds[2u * k + 1u].xyz;
    return mean + step.turbulence * perlin3_vector((p - drift) * step.turbulence_scale);
}

// turn: r by the minimal rotation taking unit a to unit b.
fn turn(a: vec3<f32>, b: vec3<f32>, r: vec3<f32>) -> vec3<f32> {
    let c = dot(a, b);
    if c < -0.9999 {
        return r - 2.0 * dot(r, a) * a;
    }
    let k = cross(a, b);
    return r * c + cross(k, r) + k * (dot(k, r) / (1.0 + c));
}

struct Root {
    position: vec3<f32>,
    frame: mat3x3<f32>,
};

// lerp_root.
fn lerp_root(s: u32, a: f32) -> Root {
    let base = 6u * s;
    let to_p = roots[base + 3u].xyz;
    let to_t = roots[base + 4u].xyz;
    let to_n = roots[base + 5u].xyz;
    if a >= 1.0 {
        return Root(to_p, mat3x3<f32>(to_t, cross(to_n, to_t), to_n));
    }
    let position = mix(roots[base].xyz, to_p, a);
    let t0 = mix(roots[base + 1u].xyz, to_t, a);
    let n = normalize_or(mix(roots[base + 2u].xyz, to_n, a), to_n);
    let t = normalize_or(t0 - n * dot(n, t0), to_t);
    return Root(position, mat3x3<f32>(t, cross(n, t), n));
}

@compute @workgroup_size(64)
fn strands_frame(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let s = id.x + id.y * groups.x * 64u;
    if s >= step.strands {
        return;
    }
    let n = step.points;
    var p: array<vec3<f32>, MAX_POINTS>;
    var correction: array<vec3<f32>, MAX_POINTS>;
    var touched: array<vec3<f32>, MAX_POINTS>;
    for (var k = 0u; k < step.substeps; k++) {
        let a = f32(k + 1u) / f32(step.substeps);
        let root = lerp_root(s, a);
        var grid_index = 0u;
        if step.grids > 1u {
            grid_index = k;
        }
        let frame = root.frame;
        // Forces.
        p[0] = root.position;
        for (var i = 1u; i < n; i++) {
            let x = positions[at(i, s)].xyz;
            var vi = velocities[at(i, s)].xyz * step.decay + step.gravity_h;
            if step.drag > 0.0 {
                vi += step.drag * (wind_at(k, x) - vi);
            }
            p[i] = x + step.h * vi;
            correction[i] = vec3<f32>(0.0);
            touched[i] = vec3<f32>(0.0);
        }
        for (var it = 0u; it < step.iterations; it++) {
            if step.follow > 0.0 {
                for (var i = 1u; i < n; i++) {
                    let goal = root.position + frame * rest[at(i, s)].xyz;
                    p[i] += step.follow * (goal - p[i]);
                }
            }
            if step.bend > 0.0 {
                var rest_prev = vec3<f32>(0.0);
                var now_prev = vec3<f32>(0.0);
                for (var i = 1u; i < n; i++) {
                    let r = frame * (rest[at(i, s)].xyz - rest[at(i - 1u, s)].xyz);
                    var goal = p[0] + r;
                    if i > 1u {
                        goal = p[i - 1u] + turn(rest_prev, now_prev, r);
                    }
                    p[i] += step.bend * (goal - p[i]);
                    rest_prev = normalize_or_zero(r);
                    now_prev = normalize_or_zero(p[i] - p[i - 1u]);
                }
            }
            for (var i = 1u; i < n; i++) {
                let before = p[i];
                let length = rest[at(i, s)].w;
                var q = p[i - 1u] + length * normalize_or(p[i] - p[i - 1u], frame[2]);
                if step.grids > 0u {
                    let g = grids[grid_index];
                    for (var c = 0u; c < COLLISION_PASSES; c++) {
                        let hit = sample(g, q);
                        if all(hit.out == vec3<f32>(0.0)) {
                            break;
                        }
                        if hit.d < step.thickness * CONTACT {
                            touched[i] = hit.out;
                        }
                        if hit.d >= step.thickness {
                            break;
                        }
                        let pushed = q + (step.thickness - hit.d) * hit.out;
                        q = p[i - 1u] + length * normalize_or(pushed - p[i - 1u], hit.out);
                        if sample(g, q).d < step.thickness * KEEP_LENGTH_WITHIN {
                            q = pushed;
                        }
                    }
                }
                p[i] = q;
                correction[i] = q - before;
            }
        }
        let inv_h = 1.0 / step.h;
        let x0 = positions[at(0u, s)].xyz;
        velocities[at(0u, s)] = vec4<f32>((p[0] - x0) * inv_h, 0.0);
        positions[at(0u, s)] = vec4<f32>(p[0], 0.0);
        for (var i = 1u; i < n; i++) {
            let x = positions[at(i, s)].xyz;
            var vi = (p[i] - x) * inv_h;
            if i + 1u < n {
                vi -= step.ftl * correction[i + 1u] * inv_h;
            }
            let normal = touched[i];
            if any(normal != vec3<f32>(0.0)) {
                let along = normal * dot(vi, normal);
                vi = along + (vi - along) * (1.0 - step.friction);
            }
            velocities[at(i, s)] = vec4<f32>(vi, 0.0);
            positions[at(i, s)] = vec4<f32>(p[i], 0.0);
        }
    }
}
