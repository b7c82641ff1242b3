//! Number formatting shared by the text writers (usda, RIB, pbrt): the
//! shortest text that reads back as the same `f32` (Ryū), integers without
//! allocation.

use glam::{Vec2, Vec3};

/// Appends the shortest decimal text that parses back to `v` (`1` rather
/// than `1.0`). `v` must be finite.
pub(crate) fn put_f32(v: f32, s: &mut Vec<u8>) {
    let mut buffer = ryu::Buffer::new();
    let text = buffer.format_finite(v);
    s.extend_from_slice(text.strip_suffix(".0").unwrap_or(text).as_bytes());
}

/// Appends `v` in decimal.
pub(crate) fn put_u64(v: u64, s: &mut Vec<u8>) {
    s.extend_from_slice(itoa::Buffer::new().format(v).as_bytes());
}

/// Appends the components of `v` separated by `sep`.
pub(crate) fn put_components(v: &[f32], sep: &[u8], s: &mut Vec<u8>) {
    for (k, &x) in v.iter().enumerate() {
        if k > 0 {
            s.extend_from_slice(sep);
        }
        put_f32(x, s);
    }
}

/// `(x, y, z)`, the usda tuple.
pub(crate) fn put_tuple3(v: &Vec3, s: &mut Vec<u8>) {
    s.push(b'(');
    put_components(&v.to_array(), b", ", s);
    s.push(b')');
}

/// `(x, y)`, the usda tuple.
pub(crate) fn put_tuple2(v: &Vec2, s: &mut Vec<u8>) {
    s.push(b'(');
    put_components(&v.to_array(), b", ", s);
    s.push(b')');
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floats_read_back_exactly_and_integers_drop_the_point() {
        for v in [
            0.0f32,
            1.0,
            -2.5,
            0.1,
            1e-7,
            3.4028235e38,
            f32::MIN_POSITIVE,
            0.30933377,
        ] {
            let mut s = Vec::new();
            put_f32(v, &mut s);
            let text = String::from_utf8(s).unwrap();
            assert_eq!(text.parse::<f32>().unwrap(), v, "{text}");
        }
        let mut s = Vec::new();
        put_f32(1.0, &mut s);
        put_u64(18_446_744_073_709_551_615, &mut s);
        assert_eq!(s, b"118446744073709551615");
    }
}
