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

// Mirrors GridHeader in strands.rs.
struct Grid {
    origin: vec3<f32>,
    cell: f32,
    nx: u32,
    ny: u32,
    nz: u32,
    far: f32,
    node_offset: u32,
    triangle_offset: u32,
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
const EXACT_WITHIN: f32 = 1.0;
const NO_TRIANGLE: u32 = 0xffffffffu;

// ---- pelage::mesh::closest_on_triangle ----

struct Closest {
    q: vec3<f32>,
    w: vec3<f32>,
};

fn closest_on_degenerate(p: vec3<f32>, a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) -> Closest {
    var best = Closest(a, vec3<f32>(1.0, 0.0, 0.0));
    var best_d = dot(a - p, a - p);
    let t = array<vec3<f32>, 3>(a, b, c);
    for (var k = 0u; k < 3u; k++) {
        let i = k;
        let j = (k + 1u) % 3u;
        let e = t[j] - t[i];
        let len2 = dot(e, e);
        var s = 0.0;
        if len2 > 0.0 {
            s = clamp(dot(p - t[i], e) / len2, 0.0, 1.0);
        }
        let q = t[i] + s * e;
        let d = dot(q - p, q - p);
        if d < best_d {
            var w = vec3<f32>(0.0);
            w[i] += 1.0 - s;
            w[j] += s;
            best = Closest(q, w);
            best_d = d;
        }
    }
    return best;
}

fn closest_on_triangle(p: vec3<f32>, a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) -> Closest {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let n = cross(ab, ac);
    if dot(n, n) <= 1.17549435e-38 {
        return closest_on_degenerate(p, a, b, c);
    }
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return Closest(a, vec3<f32>(1.0, 0.0, 0.0));
    }
    let bp = p - b;
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return Closest(b, vec3<f32>(0.0, 1.0, 0.0));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return Closest(a + v * ab, vec3<f32>(1.0 - v, v, 0.0));
    }
    let cp = p - c;
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return Closest(c, vec3<f32>(0.0, 0.0, 1.0));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return Closest(a + w * ac, vec3<f32>(1.0 - w, 0.0, w));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return Closest(b + w * (c - b), vec3<f32>(0.0, 1.0 - w, w));
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    return Closest(a + ab * v + ac * w, vec3<f32>(1.0 - v - w, v, w));
}

// ---- pelage::dynamics::SkinSdf ----

struct Sample {
    d: f32,
    out: vec3<f32>,
};

fn normalize_or_zero(v: vec3<f32>) -> vec3<f32> {
    return normalize_or(v, vec3<f32>(0.0));
}

// SkinSdf::exact: the closest of the candidate triangles, signed by the
// interpolated normal; `found` false when none is in the band.
struct Exact {
    found: bool,
    s: Sample,
};

fn exact(g: Grid, p: vec3<f32>, ids: array<u32, 8>) -> Exact {
    var best_d2 = 3.4e38;
    var best_q = vec3<f32>(0.0);
    var best_t = NO_TRIANGLE;
    var best_w = vec3<f32>(0.0);
    for (var k = 0u; k < 8u; k++) {
        let t = ids[k];
        if t == NO_TRIANGLE {
            continue;
        }
        var seen = false;
        for (var j = 0u; j < k; j++) {
            if ids[j] == t {
                seen = true;
            }
        }
        if seen {
            continue;
        }
        let base = (g.triangle_offset + t) * 6u;
        let c = closest_on_triangle(p, triangles[base].xyz, triangles[base + 1u].xyz, triangles[base + 2u].xyz);
        let d2 = dot(p - c.q, p - c.q);
        if best_t == NO_TRIANGLE || d2 < best_d2 {
            best_d2 = d2;
            best_q = c.q;
            best_t = t;
            best_w = c.w;
        }
    }
    if best_t == NO_TRIANGLE {
        return Exact(false, Sample(0.0, vec3<f32>(0.0)));
    }
    let base = (g.triangle_offset + best_t) * 6u;
    let c0 = triangles[base].xyz;
    let c1 = triangles[base + 1u].xyz;
    let c2 = triangles[base + 2u].xyz;
    let interpolated = best_w.x * triangles[base + 3u].xyz + best_w.y * triangles[base + 4u].xyz + best_w.z * triangles[base + 5u].xyz;
    let n = normalize_or(interpolated, normalize_or(cross(c1 - c0, c2 - c0), vec3<f32>(0.0, 1.0, 0.0)));
    let away = p - best_q;
    let sign = select(1.0, -1.0, dot(away, n) < 0.0);
    let d = sqrt(best_d2);
    var out = n;
    if d > 1e-6 * g.cell {
        out = sign * away / d;
    }
    return Exact(true, Sample(sign * d, out));
}

fn node(g: Grid, x: u32, y: u32, z: u32) -> u32 {
    return g.node_offset + (z * g.ny + y) * g.nx + x;
}

// SkinSdf::sample.
fn sample(g: Grid, p: vec3<f32>) -> Sample {
    let gp = (p - g.origin) / g.cell;
    if !(gp.x >= 0.0 && gp.y >= 0.0 && gp.z >= 0.0) {
        return Sample(g.far, vec3<f32>(0.0));
    }
    // Beyond u32's range reads as beyond the grid.
    if gp.x >= 4.0e9 || gp.y >= 4.0e9 || gp.z >= 4.0e9 {
        return Sample(g.far, vec3<f32>(0.0));
    }
    let ix = u32(gp.x);
    let iy = u32(gp.y);
    let iz = u32(gp.z);
    if ix + 1u >= g.nx || iy + 1u >= g.ny || iz + 1u >= g.nz {
        return Sample(g.far, vec3<f32>(0.0));
    }
    let f = gp - vec3<f32>(f32(ix), f32(iy), f32(iz));
    // The eight corner nodes: c000, c100, c010, c110, c001, c101, c011,
    // c111 (x fastest).
    let base = node(g, ix, iy, iz);
    let row = g.nx;
    let slab = g.nx * g.ny;
    var corners = array<u32, 8>(
        base, base + 1u, base + row, base + row + 1u,
        base + slab, base + slab + 1u, base + slab + row, base + slab + row + 1u,
    );
    let c000 = distances[corners[0]];
    let c100 = distances[corners[1]];
    let c010 = distances[corners[2]];
    let c110 = distances[corners[3]];
    let c001 = distances[corners[4]];
    let c101 = distances[corners[5]];
    let c011 = distances[corners[6]];
    let c111 = distances[corners[7]];
    let x00 = c000 + f.x * (c100 - c000);
    let x10 = c010 + f.x * (c110 - c010);
    let x01 = c001 + f.x * (c101 - c001);
    let x11 = c011 + f.x * (c111 - c011);
    let y0 = x00 + f.y * (x10 - x00);
    let y1 = x01 + f.y * (x11 - x01);
    let d = y0 + f.z * (y1 - y0);
    let dx0 = (c100 - c000) + f.y * ((c110 - c010) - (c100 - c000));
    let dx1 = (c101 - c001) + f.y * ((c111 - c011) - (c101 - c001));
    let dy0 = x10 - x00;
    let dy1 = x11 - x01;
    if d < EXACT_WITHIN * g.cell {
        var ids: array<u32, 8>;
        for (var k = 0u; k < 8u; k++) {
            ids[k] = nearest[corners[k]];
        }
        let e = exact(g, p, ids);
        if e.found {
            return e.s;
        }
    }
    let grad = vec3<f32>(dx0 + f.z * (dx1 - dx0), dy0 + f.z * (dy1 - dy0), y1 - y0);
    return Sample(d, normalize_or_zero(grad));
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

// glam's normalize_or: `v` made unit, or `fallback` where it cannot be.
fn normalize_or(v: vec3<f32>, fallback: vec3<f32>) -> vec3<f32> {
    let l2 = dot(v, v);
    if l2 > 0.0 && l2 < 3.4e38 {
        return v * inverseSqrt(l2);
    }
    return fallback;
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
