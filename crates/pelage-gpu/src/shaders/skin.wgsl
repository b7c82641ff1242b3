// Linear-blend skinning of a shell model's vertices, every frame before
// the layers are drawn: pelage::anim::SkinRig::pose_frames, line by line
// (the weighted matrices summed, slots of weight 0 skipped, the sum applied
// once; normals and tangents by its linear part, normalised). A test
// compares it with the CPU's within 1e-5 of the model's size.

// Mirrors the influence records of shells/model.rs: four palette indices,
// four weights.
struct Influence {
    joints: vec4<u32>,
    weights: vec4<f32>,
};

@group(0) @binding(0) var<storage, read> palette: array<mat4x4<f32>>;
// PoseVertex at rest: position, normal, tangent (9 floats a vertex).
@group(0) @binding(1) var<storage, read> rest: array<f32>;
@group(0) @binding(2) var<storage, read> influences: array<Influence>;
// PoseVertex posed: what the layers' vertex buffer reads.
@group(0) @binding(3) var<storage, read_write> pose: array<f32>;

fn rest_vec3(i: u32, k: u32) -> vec3<f32> {
    let b = 9u * i + 3u * k;
    return vec3<f32>(rest[b], rest[b + 1u], rest[b + 2u]);
}

fn store_vec3(i: u32, k: u32, v: vec3<f32>) {
    let b = 9u * i + 3u * k;
    pose[b] = v.x;
    pose[b + 1u] = v.y;
    pose[b + 2u] = v.z;
}

// Vec3::normalize_or: the fallback when the length is 0.
fn normalize_or(v: vec3<f32>, fallback: vec3<f32>) -> vec3<f32> {
    let l = length(v);
    if l > 0.0 {
        return v / l;
    }
    return fallback;
}

@compute @workgroup_size(64)
fn skin(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let i = id.x + id.y * groups.x * 64u;
    if i >= arrayLength(&influences) {
        return;
    }
    let influence = influences[i];
    var m = mat4x4<f32>(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));
    for (var k = 0u; k < 4u; k++) {
        let w = influence.weights[k];
        if w != 0.0 {
            m += palette[influence.joints[k]] * w;
        }
    }
    let linear = mat3x3<f32>(m[0].xyz, m[1].xyz, m[2].xyz);
    let p = rest_vec3(i, 0u);
    let n = rest_vec3(i, 1u);
    let t = rest_vec3(i, 2u);
    store_vec3(i, 0u, (m * vec4<f32>(p, 1.0)).xyz);
    store_vec3(i, 1u, normalize_or(linear * n, n));
    store_vec3(i, 2u, normalize_or(linear * t, t));
}
