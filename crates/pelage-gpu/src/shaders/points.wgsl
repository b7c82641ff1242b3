// Points (hair roots, samples) as camera-facing discs of a fixed size in
// pixels, anti-aliased through alpha-to-coverage, pulled slightly towards
// the camera so that points on the skin win the depth test against it.

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    // The corner of the quad in disc radii, (−1..1, −1..1).
    @location(0) corner: vec2<f32>,
};

// Mirrors PointInstance in renderer.rs (a test checks names and locations).
struct PointIn {
    @location(0) center: vec3<f32>,
};

@vertex
fn vs_main(@builtin(vertex_index) vertex: u32, point: PointIn) -> VertexOut {
    let center = point.center;
    // Two triangles: (0,1,2) (2,1,3) over corners (−1,−1) (1,−1) (−1,1) (1,1).
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(-1.0, 1.0),
        vec2<f32>(-1.0, 1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
    );
    let corner = corners[vertex];
    var clip = frame.view_proj * vec4<f32>(center, 1.0);
    // Radius in pixels → NDC (2 / size per pixel), times w for clip space.
    let radius = frame.point_radius;
    clip = vec4<f32>(clip.xy + corner * radius * 2.0 / frame.viewport_px * clip.w, clip.z - frame.point_depth_pull * clip.w, clip.w);
    var out: VertexOut;
    out.clip = clip;
    out.corner = corner;
    return out;
}

@fragment
fn fs_main(v: VertexOut) -> @location(0) vec4<f32> {
    // Coverage falls from 1 to 0 over the disc's last pixel.
    let r = length(v.corner);
    let radius = frame.point_radius;
    let coverage = clamp((1.0 - r) * radius + 0.5, 0.0, 1.0);
    return vec4<f32>(frame.point_color, coverage);
}
