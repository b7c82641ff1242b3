// pelage::map::NoiseMap::perlin3_vector, for the compute shaders that
// blow wind through fur and grow grooms. Appended to a shader that
// declares `perm_at(i)`: entry `i & 511` of the noise's doubled
// permutation table (a shader with one field reads it directly; the groom
// shader picks the current operator's table).

// pelage::map::noise::gradient3: Perlin's reference `grad`, selects and sign
// flips picking one of his sixteen gradient rows: no array indexed at run
// time, which some compilers copy into every invocation.
fn gradient3(hash: u32, d: vec3<f32>) -> f32 {
    let h = hash & 15u;
    let u = select(d.y, d.x, h < 8u);
    let v = select(select(d.z, d.x, h == 12u || h == 14u), d.y, h < 4u);
    return select(-u, u, (h & 1u) == 0u) + select(-v, v, (h & 2u) == 0u);
}

fn fade(t: vec3<f32>) -> vec3<f32> {
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
}

fn corner(hxy: u32, zi: u32, dz: u32, d: vec3<f32>) -> vec3<f32> {
    let h = perm_at(hxy + zi + dz);
    return vec3<f32>(
        gradient3(h, d),
        gradient3(perm_at(h + 101u), d),
        gradient3(perm_at(h + 203u), d),
    );
}

fn perlin3_vector(p: vec3<f32>) -> vec3<f32> {
    let cell = floor(p);
    let f = p - cell;
    let ci = vec3<u32>(vec3<i32>(cell) & vec3<i32>(255));
    let t = fade(f);
    let hx0 = perm_at(ci.x);
    let hx1 = perm_at(ci.x + 1u);
    let h00 = perm_at(hx0 + ci.y);
    let h01 = perm_at(hx0 + ci.y + 1u);
    let h10 = perm_at(hx1 + ci.y);
    let h11 = perm_at(hx1 + ci.y + 1u);
    let x00 = mix(corner(h00, ci.z, 0u, f), corner(h10, ci.z, 0u, f - vec3<f32>(1.0, 0.0, 0.0)), t.x);
    let x10 = mix(corner(h01, ci.z, 0u, f - vec3<f32>(0.0, 1.0, 0.0)), corner(h11, ci.z, 0u, f - vec3<f32>(1.0, 1.0, 0.0)), t.x);
    let x01 = mix(corner(h00, ci.z, 1u, f - vec3<f32>(0.0, 0.0, 1.0)), corner(h10, ci.z, 1u, f - vec3<f32>(1.0, 0.0, 1.0)), t.x);
    let x11 = mix(corner(h01, ci.z, 1u, f - vec3<f32>(0.0, 1.0, 1.0)), corner(h11, ci.z, 1u, f - vec3<f32>(1.0, 1.0, 1.0)), t.x);
    return mix(mix(x00, x10, t.y), mix(x01, x11, t.y), t.z);
}

