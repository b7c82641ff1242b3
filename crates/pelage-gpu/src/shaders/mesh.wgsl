// The skin: a lit triangle mesh (two-sided Lambert with a hemisphere
// ambient, optionally coloured by a texture), the surface hair grows on. Mirrors nothing in pelage::shell:
// it is preview shading only.

// The skin's colour texture (1×1 white when there is none).
@group(1) @binding(0) var skin_texture: texture_2d<f32>;
@group(1) @binding(1) var skin_sampler: sampler;

// Mirrors MeshVertex in renderer.rs (a test checks names and locations).
struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
};

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) normal: vec3<f32>,
    @location(1) uv: vec2<f32>,
};

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = frame.view_proj * vec4<f32>(v.position, 1.0);
    out.normal = v.normal;
    // UV (0, 0) is the image's bottom-left; texture rows start at the top.
    out.uv = vec2<f32>(v.uv.x, 1.0 - v.uv.y);
    return out;
}

@fragment
fn fs_main(v: VertexOut) -> @location(0) vec4<f32> {
    let n = normalize(v.normal);
    let l = frame.light_dir;
    let lambert = abs(dot(n, l));
    // Sky-ground ambient: a little brighter where the normal faces up.
    let ambient = mix(0.25, 0.4, 0.5 + 0.5 * n.y);
    let albedo = frame.skin_color * textureSample(skin_texture, skin_sampler, v.uv).rgb;
    let color = albedo * (ambient + 0.65 * lambert);
    return vec4<f32>(color, 1.0);
}
