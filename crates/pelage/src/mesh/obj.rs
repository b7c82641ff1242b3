//! Wavefront OBJ reader: `v`, `vt`, `vn` and `f` (any polygon, fan
//! triangulated; `v`, `v/vt`, `v//vn`, `v/vt/vn`; negative = relative
//! indices). Vertex colours (`v x y z r g b`) become the vertex
//! attributes `red`, `green`, `blue`; groups (`g`, or `o` in a file
//! without `g`) and materials (`usemtl`) become [`super::FaceGroups`],
//! which groom regions read. Other statements (smoothing, lines) are
//! ignored.
//!
//! Hand-written rather than tobj (a departure from the starting design, recorded in
//! ARCHITECTURE.md): tobj's errors carry no line numbers, and every error
//! here names its line. It also keeps position and UV indices apart, so UV
//! seams do not split vertices and topology stays as modelled.

use super::{FaceGroups, Mesh, MeshError, MeshErrorKind, Uvs};
use glam::{Vec2, Vec3};

/// Parses OBJ text. `name` is what errors call the file.
pub(crate) fn parse(name: &str, bytes: &[u8]) -> Result<Mesh, MeshError> {
    // Editors on Windows may start the text with a UTF-8 byte-order mark;
    // left in place it would hide the first statement.
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let mut reader = ObjReader::new(Counts::of(bytes));
    for (i, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let line_no = i + 1;
        let err = |kind| MeshError::at_line(name, line_no, kind);
        let raw = match raw.iter().position(|&b| b == b'#') {
            Some(hash) => &raw[..hash],
            None => raw,
        };
        let line = std::str::from_utf8(raw).map_err(|_| {
            err(MeshErrorKind::Syntax(
                "the line is not valid UTF-8 text".into(),
            ))
        })?;
        let mut tokens = line.split_ascii_whitespace();
        match tokens.next() {
            Some("v") => reader.vertex(tokens),
            Some("vt") => reader.uv(tokens),
            Some("vn") => reader.normal(tokens),
            Some(kind @ ("g" | "o" | "usemtl")) => {
                reader.face_set(kind, tokens);
                Ok(())
            }
            Some("f") => reader.face(tokens, line_no),
            _ => Ok(()),
        }
        .map_err(err)?;
    }
    reader.finish(name)
}

/// What a first pass over the file finds: how many vertices, UVs and
/// normals it has, so that every face index can be checked at its own
/// line even when it refers forwards, and whether it has groups (`g`),
/// which then take precedence over objects (`o`).
struct Counts {
    /// `v`, `vt` and `vn` lines.
    totals: [usize; 3],
    uses_g: bool,
}

impl Counts {
    fn of(bytes: &[u8]) -> Self {
        let mut totals = [0usize; 3];
        let mut uses_g = false;
        for line in bytes.split(|&b| b == b'\n') {
            match line.trim_ascii_start() {
                [b'v', b' ' | b'\t', ..] => totals[0] += 1,
                [b'v', b't', b' ' | b'\t', ..] => totals[1] += 1,
                [b'v', b'n', b' ' | b'\t', ..] => totals[2] += 1,
                [b'g', b' ' | b'\t', ..] => uses_g = true,
                _ => {}
            }
        }
        Self { totals, uses_g }
    }
}

/// The mesh as read so far, one statement at a time.
struct ObjReader {
    counts: Counts,
    positions: Vec<Vec3>,
    uv_values: Vec<Vec2>,
    file_normals: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    uv_triangles: Vec<[u32; 3]>,
    normal_triangles: Vec<[u32; 3]>,
    /// Whether faces carry UVs / normals, and the line of the first face,
    /// so that a file mixing faces with and without UVs can be reported.
    face_layout: Option<(bool, bool, usize)>,
    normals_on_all_faces: bool,
    corners: Vec<[Option<u32>; 3]>,
    /// Vertex colours: present on every `v` line or on none.
    colours: Vec<Vec3>,
    coloured: Option<bool>,
    /// Face sets: each kind's names and the current set of faces to come.
    sets: [FaceSets; 2],
}

impl ObjReader {
    fn new(counts: Counts) -> Self {
        let [v, vt, vn] = counts.totals;
        Self {
            positions: Vec::with_capacity(v),
            uv_values: Vec::with_capacity(vt),
            file_normals: Vec::with_capacity(vn),
            triangles: Vec::with_capacity(v * 2),
            uv_triangles: Vec::new(),
            normal_triangles: Vec::new(),
            face_layout: None,
            normals_on_all_faces: true,
            corners: Vec::with_capacity(8),
            colours: Vec::new(),
            coloured: None,
            sets: [FaceSets::new("groups"), FaceSets::new("materials")],
            counts,
        }
    }

    /// `v x y z [r g b]`.
    fn vertex<'a>(
        &mut self,
        mut tokens: impl Iterator<Item = &'a str>,
    ) -> Result<(), MeshErrorKind> {
        let [x, y, z] = numbers::<3>(&mut tokens, "a vertex (v x y z)")?;
        let p = Vec3::new(x, y, z);
        if !p.is_finite() {
            return Err(MeshErrorKind::NonFinite {
                what: "vertex position",
            });
        }
        self.positions.push(p);
        let rest: Vec<&str> = tokens.collect();
        let has_colour = rest.len() >= 3;
        match self.coloured {
            None => self.coloured = Some(has_colour),
            Some(before) if before != has_colour => {
                return Err(MeshErrorKind::Unsupported(
                    "some vertices have colours (v x y z r g b) and some do not; pelage needs colours on all vertices or on none".into(),
                ));
            }
            Some(_) => {}
        }
        if has_colour {
            let [r, g, b] = numbers::<3>(&mut rest.into_iter(), "a vertex colour")?;
            let c = Vec3::new(r, g, b);
            if !c.is_finite() {
                return Err(MeshErrorKind::NonFinite {
                    what: "vertex colour",
                });
            }
            self.colours.push(c);
        }
        Ok(())
    }

    /// `vt u [v]`.
    fn uv<'a>(&mut self, mut tokens: impl Iterator<Item = &'a str>) -> Result<(), MeshErrorKind> {
        let [u] = numbers::<1>(&mut tokens, "a texture coordinate (vt u v)")?;
        let v = match tokens.next() {
            Some(t) => number(t)?,
            None => 0.0,
        };
        let uv = Vec2::new(u, v);
        if !uv.is_finite() {
            return Err(MeshErrorKind::NonFinite {
                what: "texture coordinate",
            });
        }
        self.uv_values.push(uv);
        Ok(())
    }

    /// `vn x y z`.
    fn normal<'a>(
        &mut self,
        mut tokens: impl Iterator<Item = &'a str>,
    ) -> Result<(), MeshErrorKind> {
        let [x, y, z] = numbers::<3>(&mut tokens, "a normal (vn x y z)")?;
        let n = Vec3::new(x, y, z);
        if !n.is_finite() {
            return Err(MeshErrorKind::NonFinite {
                what: "vertex normal",
            });
        }
        self.file_normals.push(n);
        Ok(())
    }

    /// `g NAME`, `o NAME` (in a file without `g`) or `usemtl NAME`: the
    /// faces that follow are in that set.
    fn face_set<'a>(&mut self, kind: &str, tokens: impl Iterator<Item = &'a str>) {
        if kind == "o" && self.counts.uses_g {
            return;
        }
        let set = if kind == "usemtl" { 1 } else { 0 };
        let name = tokens.collect::<Vec<_>>().join(" ");
        self.sets[set].enter(if name.is_empty() { "default" } else { &name });
    }

    /// `f a b c …`: a polygon, fan triangulated as most OBJ readers do for
    /// convex polygons.
    fn face<'a>(
        &mut self,
        tokens: impl Iterator<Item = &'a str>,
        line_no: usize,
    ) -> Result<(), MeshErrorKind> {
        self.corners.clear();
        for token in tokens {
            self.corners.push(face_corner(token, &self.counts.totals)?);
        }
        let corners = &self.corners;
        if corners.len() < 3 {
            return Err(MeshErrorKind::Syntax(format!(
                "a face needs at least 3 vertices, this one has {}",
                corners.len()
            )));
        }
        let has_uv = corners.iter().all(|c| c[1].is_some());
        let has_normal = corners.iter().all(|c| c[2].is_some());
        if corners.iter().any(|c| c[1].is_some()) && !has_uv {
            return Err(MeshErrorKind::Syntax(
                "some corners of this face have texture coordinates and some do not".into(),
            ));
        }
        match self.face_layout {
            None => self.face_layout = Some((has_uv, has_normal, line_no)),
            Some((uv_before, _, first_line)) if uv_before != has_uv => {
                let (this, earlier) = if has_uv {
                    ("has", "have none")
                } else {
                    ("has no", "have them")
                };
                return Err(MeshErrorKind::Unsupported(format!(
                    "this face {this} texture coordinates (vt) and the faces before it (from line {first_line}) {earlier}; pelage needs UVs on all faces or on none"
                )));
            }
            Some(_) => {}
        }
        self.normals_on_all_faces &= has_normal;
        for k in 1..corners.len() - 1 {
            for set in &mut self.sets {
                set.add_triangle();
            }
            let tri = [corners[0], corners[k], corners[k + 1]];
            self.triangles
                .push(tri.map(|c| c[0].expect("position index is required")));
            if has_uv {
                self.uv_triangles
                    .push(tri.map(|c| c[1].expect("checked above")));
            }
            if has_normal {
                self.normal_triangles
                    .push(tri.map(|c| c[2].expect("checked above")));
            }
        }
        Ok(())
    }

    /// The mesh read, with its UVs, normals, colours and face sets.
    fn finish(self, name: &str) -> Result<Mesh, MeshError> {
        if self.positions.is_empty() {
            return Err(MeshError::whole(
                name,
                MeshErrorKind::Empty("no vertices (no 'v' lines)"),
            ));
        }
        if self.triangles.is_empty() {
            return Err(MeshError::whole(
                name,
                MeshErrorKind::Empty("no faces (no 'f' lines)"),
            ));
        }
        let uvs = self
            .face_layout
            .filter(|&(has_uv, _, _)| has_uv)
            .map(|_| Uvs::PerCorner {
                values: self.uv_values,
                indices: self.uv_triangles,
            });
        // File normals are per corner; pelage keeps one smooth normal per
        // vertex (hair follows the smooth surface), so corners are
        // averaged. Where they cancel out, the area-weighted normal is
        // used instead.
        let normals = self.normals_on_all_faces.then(|| {
            let computed = super::area_weighted_normals(&self.positions, &self.triangles);
            let mut sums = vec![Vec3::ZERO; self.positions.len()];
            for (tri, ntri) in self.triangles.iter().zip(&self.normal_triangles) {
                for k in 0..3 {
                    sums[tri[k] as usize] +=
                        self.file_normals[ntri[k] as usize].normalize_or_zero();
                }
            }
            sums.into_iter()
                .zip(computed)
                .map(|(s, c)| s.try_normalize().unwrap_or(c))
                .collect()
        });
        let mut mesh = Mesh::new(name, self.positions, self.triangles, normals, uvs)?;
        if self.coloured == Some(true) {
            for (channel, get) in [
                ("red", (|c: &Vec3| c.x) as fn(&Vec3) -> f32),
                ("green", |c| c.y),
                ("blue", |c| c.z),
            ] {
                mesh =
                    mesh.with_vertex_attribute(channel, self.colours.iter().map(get).collect())?;
            }
        }
        for set in self.sets {
            if let Some(groups) = set.finish() {
                mesh = mesh.with_face_groups(groups)?;
            }
        }
        Ok(mesh)
    }
}

/// One kind of face set as the file names them: the set each triangle
/// was in when read.
struct FaceSets {
    kind: &'static str,
    names: Vec<String>,
    current: u32,
    of_triangle: Vec<u32>,
    /// Whether the file named any set of this kind.
    named: bool,
}

impl FaceSets {
    fn new(kind: &'static str) -> Self {
        Self {
            kind,
            names: vec!["default".into()],
            current: 0,
            of_triangle: Vec::new(),
            named: false,
        }
    }

    fn enter(&mut self, name: &str) {
        self.named = true;
        self.current = match self.names.iter().position(|n| n == name) {
            Some(i) => i as u32,
            None => {
                self.names.push(name.to_string());
                self.names.len() as u32 - 1
            }
        };
    }

    fn add_triangle(&mut self) {
        self.of_triangle.push(self.current);
    }

    fn finish(self) -> Option<FaceGroups> {
        self.named.then(|| FaceGroups {
            kind: self.kind.to_string(),
            names: self.names,
            of_triangle: self.of_triangle,
        })
    }
}

/// Parses `N` numbers from `tokens`; `what` describes the statement for the
/// error when there are too few.
fn numbers<'a, const N: usize>(
    tokens: &mut impl Iterator<Item = &'a str>,
    what: &str,
) -> Result<[f32; N], MeshErrorKind> {
    let mut out = [0.0; N];
    for (k, slot) in out.iter_mut().enumerate() {
        let token = tokens
            .next()
            .ok_or_else(|| MeshErrorKind::Syntax(format!("{what} needs {N} numbers, found {k}")))?;
        *slot = number(token)?;
    }
    Ok(out)
}

fn number(token: &str) -> Result<f32, MeshErrorKind> {
    let value = token
        .parse::<f32>()
        .map_err(|_| MeshErrorKind::Syntax(format!("cannot read {token:?} as a number")))?;
    // A finite number beyond f32's range parses as infinity: say so, rather
    // than call the file's 1e39 "NaN or infinity".
    if value.is_infinite() && token.parse::<f64>().is_ok_and(f64::is_finite) {
        return Err(MeshErrorKind::Syntax(format!(
            "{token} is too large: coordinates are 32-bit floats, at most ±3.4e38"
        )));
    }
    Ok(value)
}

/// One face corner, `v`, `v/vt`, `v//vn` or `v/vt/vn`, resolved to 0-based
/// indices checked against the file's totals of v, vt and vn.
fn face_corner(token: &str, totals: &[usize; 3]) -> Result<[Option<u32>; 3], MeshErrorKind> {
    const KINDS: [(&str, &str); 3] = [("vertex", "vertices"), ("uv", "uvs"), ("normal", "normals")];
    let mut out = [None; 3];
    let mut parts = token.split('/');
    for (k, slot) in out.iter_mut().enumerate() {
        let Some(part) = parts.next() else { break };
        if part.is_empty() {
            if k == 0 {
                return Err(MeshErrorKind::Syntax(format!(
                    "face corner {token:?} has no vertex index"
                )));
            }
            continue;
        }
        let raw: i64 = part.parse().map_err(|_| {
            MeshErrorKind::Syntax(format!(
                "cannot read {part:?} in face corner {token:?} as an index"
            ))
        })?;
        let count = totals[k];
        let (what, what_plural) = KINDS[k];
        let out_of_range = |hint| MeshErrorKind::IndexOutOfRange {
            what,
            what_plural,
            index: raw,
            count,
            hint,
        };
        // OBJ indices are 1-based; negative ones count back from the end.
        let resolved = match raw {
            0 => return Err(out_of_range("; OBJ indices start at 1")),
            r if r > 0 => r - 1,
            r => count as i64 + r,
        };
        if resolved < 0 || resolved >= count as i64 {
            return Err(out_of_range(""));
        }
        *slot = Some(resolved as u32);
    }
    if parts.next().is_some() {
        return Err(MeshErrorKind::Syntax(format!(
            "face corner {token:?} has more than three '/'-separated indices"
        )));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quad_is_fan_triangulated_with_uvs_per_corner() {
        let text = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n";
        let m = parse("quad.obj", text).unwrap();
        assert_eq!(m.triangles(), &[[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.triangle_uvs(1).unwrap()[2], Vec2::new(0.0, 1.0));
        assert!((m.surface_area() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn vertex_colours_and_face_sets_are_kept() {
        let text = "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0 0 0 1\nv 0 1 0 1 1 1\nf 1 2 3\ng left side\nusemtl fur\nf 1 3 4\ng right\nf 1 2 4\n";
        let m = parse("c.obj", text.as_bytes()).unwrap();
        assert_eq!(
            &m.vertex_attribute("green").unwrap().values[..],
            &[0.0, 1.0, 0.0, 1.0]
        );
        let g = m.face_groups("groups").unwrap();
        assert_eq!(g.names, ["default", "left side", "right"]);
        assert_eq!(g.of_triangle, [0, 1, 2]);
        let mtl = m.face_groups("materials").unwrap();
        assert_eq!(mtl.names, ["default", "fur"]);
        assert_eq!(mtl.of_triangle, [0, 1, 1]);
        // Subdivision keeps both: children in their parent's set.
        let s = m.subdivided(1);
        assert_eq!(s.face_groups("groups").unwrap().of_triangle[4..8], [1; 4]);
        assert_eq!(
            s.vertex_attribute("red").unwrap().values.len(),
            s.vertex_count()
        );
        let err = parse("c.obj", b"v 0 0 0 1 0 0\nv 1 0 0\n")
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("c.obj:2:"), "{err}");
    }

    #[test]
    fn negative_indices_are_relative() {
        let m = parse("rel.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n").unwrap();
        assert_eq!(m.triangles(), &[[0, 1, 2]]);
    }

    #[test]
    fn file_normals_are_used() {
        let text = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 -1\nf 1//1 2//1 3//1\n";
        let m = parse("n.obj", text).unwrap();
        assert_eq!(m.normals()[0], Vec3::NEG_Z);
    }

    #[test]
    fn index_zero_is_reported_at_its_line() {
        let err = parse("zero.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 0 1 2\n").unwrap_err();
        assert_eq!(
            err.to_string(),
            "zero.obj:5: vertex index 0 is out of range: there are 3 vertices; OBJ indices start at 1"
        );
    }
}
