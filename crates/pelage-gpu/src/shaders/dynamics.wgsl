// One explicit substep — or, where no springs join the tips, one implicit
// step — of a mass-spring system (Banisch & Wüthrich; Silva
// §3.2.1), one invocation a tip: force, velocity, position, constraints —
// the fused pass of pelage::dynamics::solver's explicit solver, read from
// one state buffer and written to the other. Every function mirrors the
// Rust one named the same; keep them in step (tests/dynamics.rs steps both
// and compares).

// Mirrors StepUniform in dynamics.rs (a test checks names and offsets).
struct Step {
    // Acceleration.
    gravity: vec3<f32>,
    // The substep.
    h: f32,
    mass: f32,
    stiffness: f32,
    lateral_stiffness: f32,
    damping: f32,
    drag: f32,
    // Banisch's restoring w (Eq. 5).
    restoring: f32,
    // The wind's turbulence speed (no wind: 0).
    turbulence: f32,
    turbulence_scale: f32,
    // The wind's gusting mean now.
    wind_mean: vec3<f32>,
    // 0: no brush.
    brush_radius: f32,
    // The turbulence's drift now.
    wind_drift: vec3<f32>,
    tips: u32,
    brush_centre: vec3<f32>,
    // 1 for Silva strands (a spring to p0, a length limit).
    silva_strands: u32,
    brush_force: vec3<f32>,
    pad0: f32,
};

@group(0) @binding(0) var<uniform> step: Step;
// xyz: root, w: rest length L0.
@group(0) @binding(1) var<storage, read> roots: array<vec4<f32>>;
// xyz: unit rest direction n.
@group(0) @binding(2) var<storage, read> normals: array<vec4<f32>>;
// xyz: root velocity.
@group(0) @binding(3) var<storage, read> root_velocities: array<vec4<f32>>;
// Tip i's tip-tip springs are spring_ends[spring_offsets[i] ..
// spring_offsets[i + 1]]: (other tip, bitcast rest length).
@group(0) @binding(4) var<storage, read> spring_offsets: array<u32>;
@group(0) @binding(5) var<storage, read> spring_ends: array<vec2<u32>>;
// The turbulence's doubled permutation table.
@group(0) @binding(6) var<storage, read> permutation: array<u32>;

// noise.wgsl's table lookup: this shader's one field.
fn perm_at(i: u32) -> u32 {
    return permutation[i & 511u];
}
@group(0) @binding(7) var<storage, read> tips_in: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read> velocities_in: array<vec4<f32>>;
@group(0) @binding(9) var<storage, read_write> tips_out: array<vec4<f32>>;
@group(0) @binding(10) var<storage, read_write> velocities_out: array<vec4<f32>>;

// ---- pelage::dynamics::solver ----

// WindNow::at.
fn wind_at(p: vec3<f32>) -> vec3<f32> {
    let turbulence = step.turbulence;
    if turbulence == 0.0 {
        return step.wind_mean;
    }
    return step.wind_mean + turbulence * perlin3_vector((p - step.wind_drift) * step.turbulence_scale);
}

// MassSpringSystem::tip_force.
fn tip_force(i: u32, x: vec3<f32>, v: vec3<f32>) -> vec3<f32> {
    let root = roots[i].xyz;
    let rest_length = roots[i].w;
    let n = normals[i].xyz;
    let v_rel = v - root_velocities[i].xyz;
    let d = x - root;
    let l = length(d);
    var dir = n;
    if l > 1e-12 {
        dir = d / l;
    }
    var f: vec3<f32>;
    if step.silva_strands != 0u {
        f = -step.stiffness * (x - (root + rest_length * n)) - step.damping * v_rel;
    } else {
        let stretch = -step.stiffness * (l - rest_length) * dir;
        // Banisch Eq. 5.
        let restoring = (n - dir) * (1.0 - dot(n, dir)) * step.restoring;
        f = stretch - step.damping * dot(v_rel, dir) * dir + restoring;
    }
    f += step.mass * step.gravity;
    f += step.drag * (wind_at(x) - v);
    let radius = step.brush_radius;
    if radius > 0.0 {
        let q = distance(x, step.brush_centre) / max(radius, 1e-9);
        if q < 1.0 {
            let fade = 1.0 - q * q;
            f += step.brush_force * fade * fade;
        }
    }
    return f;
}

// MassSpringSystem::lateral_force.
fn lateral_force(i: u32, x: vec3<f32>, v: vec3<f32>) -> vec3<f32> {
    var f = vec3<f32>(0.0);
    for (var s = spring_offsets[i]; s < spring_offsets[i + 1u]; s += 1u) {
        let end = spring_ends[s];
        let d = x - tips_in[end.x].xyz;
        let l = length(d);
        if l <= 1e-12 {
            continue;
        }
        let dir = d / l;
        let dv = v - velocities_in[end.x].xyz;
        let rest = bitcast<f32>(end.y);
        f += -step.lateral_stiffness * (l - rest) * dir - step.damping * dot(dv, dir) * dir;
    }
    return f;
}

struct TipState {
    x: vec3<f32>,
    v: vec3<f32>,
};

// MassSpringSystem::constrained.
fn constrained(i: u32, x_in: vec3<f32>, v_in: vec3<f32>) -> TipState {
    var x = x_in;
    var v = v_in;
    let root = roots[i].xyz;
    let rest_length = roots[i].w;
    let n = normals[i].xyz;
    let root_velocity = root_velocities[i].xyz;
    let height = dot(x - root, n);
    if height < 0.0 {
        x -= height * n;
        let vn = dot(v - root_velocity, n);
        if vn < 0.0 {
            v -= vn * n;
        }
    }
    if step.silva_strands != 0u {
        let d = x - root;
        let l = length(d);
        if l > rest_length {
            let dir = d / l;
            x = root + rest_length * dir;
            let vr = dot(v - root_velocity, dir);
            if vr > 0.0 {
                v -= vr * dir;
            }
        }
    }
    return TipState(x, v);
}

// The element (tip, or triangle corner) an invocation works on. Millions
// of them need more workgroups than one dispatch dimension holds
// (65,535), so the host spreads them over x and y.
fn flat_index(id: vec3<u32>, groups: vec3<u32>) -> u32 {
    return id.y * groups.x * 64u + id.x;
}

fn store(i: u32, next: TipState) {
    tips_out[i] = vec4<f32>(next.x, 0.0);
    velocities_out[i] = vec4<f32>(next.v, 0.0);
}

@compute @workgroup_size(64)
fn explicit_substep(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let i = flat_index(id, groups);
    if i >= step.tips {
        return;
    }
    let h = step.h;
    let x = tips_in[i].xyz;
    let v0 = velocities_in[i].xyz;
    let f = tip_force(i, x, v0) + lateral_force(i, x, v0);
    let v = v0 + (h / step.mass) * f;
    store(i, constrained(i, x + h * v, v));
}

// ---- the implicit step where no springs join the tips ----

// pelage::dynamics::solver::outer: d dᵀ.
fn outer(d: vec3<f32>) -> mat3x3<f32> {
    return mat3x3<f32>(d * d.x, d * d.y, d * d.z);
}

// MassSpringSystem::stick_blocks: the stick's −∂F/∂x (k) and −∂F/∂v (c)
// blocks, with solver::spring_stiffness's clamp (compressed sticks keep
// the matrix positive semi-definite).
struct Blocks {
    k: mat3x3<f32>,
    c: mat3x3<f32>,
};

fn stick_blocks(i: u32, x: vec3<f32>) -> Blocks {
    let identity = mat3x3<f32>(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, 0.0, 1.0));
    if step.silva_strands != 0u {
        return Blocks(step.stiffness * identity, step.damping * identity);
    }
    let d = x - roots[i].xyz;
    let l = length(d);
    if l <= 1e-12 {
        return Blocks(step.stiffness * identity, mat3x3<f32>());
    }
    let dir = d / l;
    let o = outer(dir);
    let tangential = max(1.0 - roots[i].w / l, 0.0);
    return Blocks(step.stiffness * (tangential * (identity - o) + o), step.damping * o);
}

// glam's Mat3::inverse: the adjugate's rows are cross products of the
// columns, over the determinant.
fn inverse3(a: mat3x3<f32>) -> mat3x3<f32> {
    let r0 = cross(a[1], a[2]);
    let r1 = cross(a[2], a[0]);
    let r2 = cross(a[0], a[1]);
    let inv_det = 1.0 / dot(a[2], r2);
    return transpose(mat3x3<f32>(r0 * inv_det, r1 * inv_det, r2 * inv_det));
}

// MassSpringSystem::implicit_step_unjoined: one linearised backward-Euler
// step, (M + h C + h² K) Δv = h (F − h K v), each tip's 3×3 block solved
// directly (no tip-tip springs: the matrix is block diagonal).
@compute @workgroup_size(64)
fn implicit_unjoined_step(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let i = flat_index(id, groups);
    if i >= step.tips {
        return;
    }
    let h = step.h;
    let x = tips_in[i].xyz;
    let v0 = velocities_in[i].xyz;
    let f = tip_force(i, x, v0);
    let blocks = stick_blocks(i, x);
    let fixed = step.mass + h * step.drag;
    let a = mat3x3<f32>(vec3<f32>(fixed, 0.0, 0.0), vec3<f32>(0.0, fixed, 0.0), vec3<f32>(0.0, 0.0, fixed))
        + h * blocks.c + (h * h) * blocks.k;
    let dv = inverse3(a) * (h * (f - h * (blocks.k * v0)));
    let v = v0 + dv;
    store(i, constrained(i, x + h * v, v));
}

// ---- coupling to the shells: MassSpringSystem::corner_tip_offsets ----

// For each triangle corner, the stick it follows; for each vertex of the
// shell model, a triangle corner it stands for; and the renderer's
// per-vertex tip offsets p − p0 (three floats a vertex, its vertex buffer).
@group(0) @binding(11) var<storage, read> corner_sticks: array<u32>;
@group(0) @binding(12) var<storage, read_write> vertex_offsets: array<f32>;
@group(0) @binding(13) var<storage, read> vertex_corners: array<u32>;

@compute @workgroup_size(64)
fn corner_tip_offsets(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let r = flat_index(id, groups);
    if r >= arrayLength(&vertex_corners) {
        return;
    }
    let s = corner_sticks[vertex_corners[r]];
    let rest_tip = roots[s].xyz + roots[s].w * normals[s].xyz;
    let offset = tips_in[s].xyz - rest_tip;
    vertex_offsets[3u * r] = offset.x;
    vertex_offsets[3u * r + 1u] = offset.y;
    vertex_offsets[3u * r + 2u] = offset.z;
}
