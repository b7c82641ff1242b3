// pelage::dynamics::SkinSdf's queries (and the closest point on a
// triangle they read), shared by the compute shaders that keep points out
// of a skin: the guide strands' (strands.wgsl) and the groom's
// (groom.wgsl). Appended to a shader that defines where a grid's values
// are: `sdf_distance(g, node)`, `sdf_nearest(g, node)` (a node's nearest
// triangle) and `sdf_triangle(g, i)` (vector `i` of the triangles' six:
// corners, then corners' normals).

const EXACT_WITHIN: f32 = 1.0;
const NO_TRIANGLE: u32 = 0xffffffffu;

// Mirrors GridHeader in pelage-gpu's strands.rs (a test checks names and
// offsets).
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

// glam's normalize_or: `v` made unit, or `fallback` where it cannot be.
fn normalize_or(v: vec3<f32>, fallback: vec3<f32>) -> vec3<f32> {
    let l2 = dot(v, v);
    if l2 > 0.0 && l2 < 3.4e38 {
        return v * inverseSqrt(l2);
    }
    return fallback;
}

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
        let c = closest_on_triangle(p, sdf_triangle(g, base), sdf_triangle(g, base + 1u), sdf_triangle(g, base + 2u));
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
    let c0 = sdf_triangle(g, base);
    let c1 = sdf_triangle(g, base + 1u);
    let c2 = sdf_triangle(g, base + 2u);
    let interpolated = best_w.x * sdf_triangle(g, base + 3u) + best_w.y * sdf_triangle(g, base + 4u) + best_w.z * sdf_triangle(g, base + 5u);
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
    let c000 = sdf_distance(g, corners[0]);
    let c100 = sdf_distance(g, corners[1]);
    let c010 = sdf_distance(g, corners[2]);
    let c110 = sdf_distance(g, corners[3]);
    let c001 = sdf_distance(g, corners[4]);
    let c101 = sdf_distance(g, corners[5]);
    let c011 = sdf_distance(g, corners[6]);
    let c111 = sdf_distance(g, corners[7]);
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
            ids[k] = sdf_nearest(g, corners[k]);
        }
        let e = exact(g, p, ids);
        if e.found {
            return e.s;
        }
    }
    let grad = vec3<f32>(dx0 + f.z * (dx1 - dx0), dy0 + f.z * (dy1 - dy0), y1 - y0);
    return Sample(d, normalize_or(grad, vec3<f32>(0.0)));
}

// SkinSdf::clear_of: whether `p` is certainly `gap` or more outside the
// skin, from the grid's nodes alone (a node `d` outside keeps every point
// `r` from it at least `d − r` outside); beyond the grid, outside.
fn clear_of(g: Grid, p: vec3<f32>, gap: f32) -> bool {
    if gap > EXACT_WITHIN * g.cell {
        return false;
    }
    let gp = (p - g.origin) / g.cell;
    if !(gp.x >= 0.0 && gp.y >= 0.0 && gp.z >= 0.0) {
        return true;
    }
    if gp.x >= 4.0e9 || gp.y >= 4.0e9 || gp.z >= 4.0e9 {
        return true;
    }
    let ix = u32(gp.x);
    let iy = u32(gp.y);
    let iz = u32(gp.z);
    if ix + 1u >= g.nx || iy + 1u >= g.ny || iz + 1u >= g.nz {
        return true;
    }
    let f = gp - vec3<f32>(f32(ix), f32(iy), f32(iz));
    let base = node(g, ix, iy, iz);
    // The corner nearest the point first: it gives the best bound.
    let near = vec3<u32>(select(0u, 1u, f.x >= 0.5), select(0u, 1u, f.y >= 0.5), select(0u, 1u, f.z >= 0.5));
    for (var k = 0u; k < 8u; k++) {
        let o = near ^ vec3<u32>(k & 1u, (k >> 1u) & 1u, (k >> 2u) & 1u);
        let d = sdf_distance(g, base + (o.z * g.ny + o.y) * g.nx + o.x);
        // Nodes beyond the band hold `far` on either side: they say nothing.
        if d < gap || d >= g.far {
            continue;
        }
        let r = length(f - vec3<f32>(o)) * g.cell;
        if d - r >= gap {
            return true;
        }
    }
    return false;
}
