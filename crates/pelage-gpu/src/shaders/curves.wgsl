// Hair curves as camera-facing ribbons: one instance per segment (two
// points with their widths), expanded across the segment's direction on
// screen. Ribbons thinner than a pixel are drawn one pixel wide with their
// coverage scaled down (through alpha-to-coverage), so thin hair thins
// instead of shimmering. Shading: Kajiya-Kay (1989) along the tangent —
// diffuse sin(T, L), specular sin(T, H)^p — preview shading, not the shell
// fur's Eq. 6.

// Mirrors SegmentInstance in renderer.rs (a test checks names and
// locations).
struct SegmentIn {
    // xyz: first point, w: its width.
    @location(0) a: vec4<f32>,
    // xyz: second point, w: its width.
    @location(1) b: vec4<f32>,
    // rgb: the first point's colour; a: 1 where the curves have colours,
    // 0 to use the style's hair colour.
    @location(2) color_a: vec4<f32>,
    // The second point's colour.
    @location(3) color_b: vec4<f32>,
};

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) tangent: vec3<f32>,
    @location(1) world: vec3<f32>,
    @location(2) coverage: f32,
    @location(3) color: vec4<f32>,
};

@vertex
fn vs_main(@builtin(vertex_index) vertex: u32, s: SegmentIn) -> VertexOut {
    // Two triangles over (t, side): (0,−1) (1,−1) (0,1) / (0,1) (1,−1) (1,1).
    var ts = array<f32, 6>(0.0, 1.0, 0.0, 0.0, 1.0, 1.0);
    var sides = array<f32, 6>(-1.0, -1.0, 1.0, 1.0, -1.0, 1.0);
    let t = ts[vertex];
    let p = mix(s.a.xyz, s.b.xyz, t);
    let width = mix(s.a.w, s.b.w, t);
    let half_size = 0.5 * frame.viewport_px;
    let ca = frame.view_proj * vec4<f32>(s.a.xyz, 1.0);
    let cb = frame.view_proj * vec4<f32>(s.b.xyz, 1.0);
    let clip = frame.view_proj * vec4<f32>(p, 1.0);
    var direction = cb.xy / cb.w * half_size - ca.xy / ca.w * half_size;
    if (length(direction) < 1e-6) {
        direction = vec2<f32>(1.0, 0.0);
    }
    let across = normalize(vec2<f32>(-direction.y, direction.x));
    // World width → pixels at this depth.
    let width_px = width * frame.focal_length_px / clip.w;
    let drawn_px = max(width_px, 1.0);
    let offset_px = across * sides[vertex] * 0.5 * drawn_px;
    var out: VertexOut;
    out.clip = vec4<f32>(clip.xy + offset_px / half_size * clip.w, clip.zw);
    out.tangent = s.b.xyz - s.a.xyz;
    out.world = p;
    out.coverage = clamp(width_px, 0.0, 1.0);
    out.color = mix(s.color_a, s.color_b, t);
    return out;
}

@fragment
fn fs_main(v: VertexOut) -> @location(0) vec4<f32> {
    let tangent = normalize(v.tangent);
    let l = frame.light_dir;
    let to_eye = normalize(frame.eye - v.world);
    let h = normalize(l + to_eye);
    let cos_tl = dot(tangent, l);
    let cos_th = dot(tangent, h);
    let diffuse = sqrt(max(0.0, 1.0 - cos_tl * cos_tl));
    let specular = pow(sqrt(max(0.0, 1.0 - cos_th * cos_th)), 60.0);
    let base = mix(frame.hair_color, v.color.rgb, v.color.a);
    let color = base * (0.3 + 0.7 * diffuse) + vec3<f32>(frame.hair_specular * specular);
    return vec4<f32>(color, v.coverage);
}
