//! Curves for renderers that read scene text: RenderMan RIB and pbrt-v4.
//!
//! Both get the same curve USD's pinned Catmull-Rom describes, so a groom
//! looks the same in every renderer: the spline passes through every point,
//! with USD's phantom end points `P[-1] = 2 P[0] − P[1]` and
//! `P[n] = 2 P[n−1] − P[n−2]`.
//!
//! - RIB: one `Curves "cubic" … "nonperiodic"` call per block of curves
//!   under `Basis "catmull-rom"`, the phantom points written out, widths
//!   `varying` (one per original point); `Cs`/`Os` when the curves have
//!   colours/opacities. Linear curves become `Curves "linear"`.
//! - pbrt-v4: one `Shape "curve"` per hair, its Catmull-Rom segments
//!   converted to cubic Bézier control points (`b1 = p1 + (p2 − p0)/6`,
//!   `b2 = p2 − (p3 − p1)/6`), `"float width0"` at the root and `"float
//!   width1"` at the tip (pbrt interpolates linearly between them; other
//!   width profiles and colours are not expressible per curve there).
//!   Linear curves become Bézier segments with control points at thirds.

use super::CurveBasis;
use super::text::{put_components, put_f32, put_u64};
use crate::Curves;
use glam::Vec3;
use std::io::Write;

/// Curves per RIB `Curves` call: bounds the size of each call.
const RIB_BLOCK: usize = 16_384;

fn check_lengths(curves: &Curves, format: &str) -> std::io::Result<()> {
    match (0..curves.curve_count()).find(|&i| curves.range(i).len() < 2) {
        Some(i) => Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!(
                "curve {i} has {} point(s); {format} curves need at least 2",
                curves.range(i).len()
            ),
        )),
        None => Ok(()),
    }
}

/// The curve's points with USD's pinned phantom points at both ends.
fn with_phantoms(p: &[Vec3]) -> impl Iterator<Item = Vec3> + '_ {
    let n = p.len();
    let first = 2.0 * p[0] - p[1];
    let last = 2.0 * p[n - 1] - p[n - 2];
    std::iter::once(first)
        .chain(p.iter().copied())
        .chain(std::iter::once(last))
}

/// Writes RIB: `Basis` and `Curves` calls inside an attribute block.
pub fn write_rib(out: &mut impl Write, curves: &Curves, basis: CurveBasis) -> std::io::Result<()> {
    check_lengths(curves, "RIB")?;
    writeln!(
        out,
        "##RenderMan RIB\n# pelage curves: {} hairs\nAttributeBegin",
        curves.curve_count()
    )?;
    let cubic = basis == CurveBasis::CatmullRom;
    if cubic {
        writeln!(out, "  Basis \"catmull-rom\" 1 \"catmull-rom\" 1")?;
    }
    let ids: Vec<usize> = (0..curves.curve_count()).collect();
    let mut s = Vec::new();
    for block in ids.chunks(RIB_BLOCK) {
        s.clear();
        let kind = if cubic { "cubic" } else { "linear" };
        s.extend_from_slice(format!("  Curves \"{kind}\" [").as_bytes());
        for (k, &c) in block.iter().enumerate() {
            if k > 0 {
                s.push(b' ');
            }
            put_u64(
                (curves.range(c).len() + if cubic { 2 } else { 0 }) as u64,
                &mut s,
            );
        }
        s.extend_from_slice(b"] \"nonperiodic\"\n    \"P\" [");
        let mut first = true;
        for &c in block {
            let p = &curves.points()[curves.range(c)];
            let mut put = |v: Vec3| {
                if !first {
                    s.push(b' ');
                }
                first = false;
                put_components(&v.to_array(), b" ", &mut s);
            };
            if cubic {
                with_phantoms(p).for_each(&mut put);
            } else {
                p.iter().copied().for_each(&mut put);
            }
        }
        s.extend_from_slice(b"]\n    \"width\" [");
        // varying: one value per original point for both bases.
        let per_point = |s: &mut Vec<u8>, values: &[f32], width: usize| {
            let mut first = true;
            for &c in block {
                let r = curves.range(c);
                for v in values[r.start * width..r.end * width].chunks(width) {
                    if !first {
                        s.push(b' ');
                    }
                    first = false;
                    put_components(v, b" ", s);
                }
            }
        };
        per_point(&mut s, curves.widths(), 1);
        s.push(b']');
        if let Some(colors) = curves.colors() {
            s.extend_from_slice(b"\n    \"varying color Cs\" [");
            let flat: Vec<f32> = colors.iter().flat_map(|c| c.to_array()).collect();
            per_point(&mut s, &flat, 3);
            s.push(b']');
        }
        if let Some(opacities) = curves.opacities() {
            s.extend_from_slice(b"\n    \"varying color Os\" [");
            let flat: Vec<f32> = opacities.iter().flat_map(|&o| [o, o, o]).collect();
            per_point(&mut s, &flat, 3);
            s.push(b']');
        }
        s.push(b'\n');
        out.write_all(&s)?;
    }
    writeln!(out, "AttributeEnd")
}

/// Cubic Bézier control points (3 per segment + 1) of a curve.
pub fn bezier_control_points(p: &[Vec3], basis: CurveBasis) -> Vec<Vec3> {
    let mut b = vec![p[0]];
    match basis {
        CurveBasis::Linear => {
            for w in p.windows(2) {
                b.extend([w[0].lerp(w[1], 1.0 / 3.0), w[0].lerp(w[1], 2.0 / 3.0), w[1]]);
            }
        }
        CurveBasis::CatmullRom => {
            let q: Vec<Vec3> = with_phantoms(p).collect();
            for w in q.windows(4) {
                b.extend([w[1] + (w[2] - w[0]) / 6.0, w[2] - (w[3] - w[1]) / 6.0, w[2]]);
            }
        }
    }
    b
}

/// Writes pbrt-v4 shapes, one `Shape "curve"` per hair (`Include` the file
/// inside a pbrt scene's world block).
pub fn write_pbrt(out: &mut impl Write, curves: &Curves, basis: CurveBasis) -> std::io::Result<()> {
    check_lengths(curves, "pbrt")?;
    writeln!(
        out,
        "# pelage curves: {} hairs (pbrt-v4; Include inside WorldBegin)",
        curves.curve_count()
    )?;
    let mut s = Vec::new();
    for c in 0..curves.curve_count() {
        let r = curves.range(c);
        s.clear();
        s.extend_from_slice(b"Shape \"curve\" \"string type\" \"cylinder\" \"point3 P\" [");
        for (k, v) in bezier_control_points(&curves.points()[r.clone()], basis)
            .iter()
            .enumerate()
        {
            if k > 0 {
                s.push(b' ');
            }
            put_components(&v.to_array(), b" ", &mut s);
        }
        s.extend_from_slice(b"] \"float width0\" ");
        put_f32(curves.widths()[r.start], &mut s);
        s.extend_from_slice(b" \"float width1\" ");
        put_f32(curves.widths()[r.end - 1], &mut s);
        s.push(b'\n');
        out.write_all(&s)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Catmull-Rom through p1, p2 with neighbours p0, p3, at t.
    fn catmull_rom(p: [Vec3; 4], t: f32) -> Vec3 {
        let (t2, t3) = (t * t, t * t * t);
        0.5 * ((2.0 * p[1])
            + (p[2] - p[0]) * t
            + (2.0 * p[0] - 5.0 * p[1] + 4.0 * p[2] - p[3]) * t2
            + (3.0 * p[1] - p[0] - 3.0 * p[2] + p[3]) * t3)
    }

    fn bezier(b: &[Vec3], t: f32) -> Vec3 {
        let s = 1.0 - t;
        b[0] * s * s * s + b[1] * 3.0 * s * s * t + b[2] * 3.0 * s * t * t + b[3] * t * t * t
    }

    #[test]
    fn bezier_segments_trace_the_pinned_catmull_rom_curve() {
        let p = [
            Vec3::ZERO,
            Vec3::new(1.0, 2.0, 0.0),
            Vec3::new(3.0, 2.5, 1.0),
            Vec3::new(4.0, 0.0, 2.0),
        ];
        let b = bezier_control_points(&p, CurveBasis::CatmullRom);
        assert_eq!(b.len(), 3 * (p.len() - 1) + 1);
        let q: Vec<Vec3> = with_phantoms(&p).collect();
        for seg in 0..p.len() - 1 {
            for k in 0..=8 {
                let t = k as f32 / 8.0;
                let want = catmull_rom([q[seg], q[seg + 1], q[seg + 2], q[seg + 3]], t);
                let got = bezier(&b[3 * seg..3 * seg + 4], t);
                assert!(
                    (want - got).length() < 1e-5,
                    "segment {seg} t {t}: {want} vs {got}"
                );
            }
        }
        // Pinned: the curve passes through the first and last points.
        assert_eq!((b[0], *b.last().unwrap()), (p[0], p[3]));
    }

    #[test]
    fn rib_counts_include_the_phantom_points_and_widths_stay_per_point() {
        let curves = Curves::new(
            vec![
                Vec3::ZERO,
                Vec3::Y,
                Vec3::new(0.0, 2.0, 0.0),
                Vec3::X,
                Vec3::ONE,
            ],
            vec![0.1, 0.2, 0.3, 0.4, 0.5],
            vec![0, 3, 5],
        )
        .unwrap();
        let mut out = Vec::new();
        write_rib(&mut out, &curves, CurveBasis::CatmullRom).unwrap();
        let text = String::from_utf8(out).unwrap();
        assert!(
            text.contains("Curves \"cubic\" [5 4] \"nonperiodic\""),
            "{text}"
        );
        assert!(
            text.contains("\"P\" [0 -1 0 0 0 0 0 1 0 0 2 0 0 3 0 1 -1 -1 1 0 0 1 1 1 1 2 2]"),
            "{text}"
        );
        assert!(text.contains("\"width\" [0.1 0.2 0.3 0.4 0.5]"), "{text}");
        let mut out = Vec::new();
        let single = Curves::new(vec![Vec3::ZERO], vec![0.1], vec![0, 1]).unwrap();
        assert!(
            write_rib(&mut out, &single, CurveBasis::Linear)
                .unwrap_err()
                .to_string()
                .contains("curve 0 has 1 point")
        );
    }
}
