// The skin: a lit triangle mesh (two-sided Lambert with a hemisphere
// ambient), the surface hair grows on. Mirrors nothing in pelage::shell:
// it is preview shading only.

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
};

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) normal: vec3<f32>,
};

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = frame.view_proj * vec4<f32>(v.position, 1.0);
    out.normal = v.normal;
    return out;
}

@fragment
fn fs_main(v: VertexOut) -> @location(0) vec4<f32> {
    let n = normalize(v.normal);
    let l = frame.light_dir.xyz;
    let lambert = abs(dot(n, l));
    // Sky-ground ambient: a little brighter where the normal faces up.
    let ambient = mix(0.25, 0.4, 0.5 + 0.5 * n.y);
    let color = frame.skin_color.rgb * (ambient + 0.65 * lambert);
    return vec4<f32>(color, 1.0);
}
