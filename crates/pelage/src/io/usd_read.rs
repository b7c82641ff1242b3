//! Curves from USD (usda or usdc): every `BasisCurves` prim of the layer,
//! in path order, concatenated, with its ancestors' transforms applied — what
//! pelage's writer and Blender's USD export write.
//!
//! Text layers are parsed by the `openusd` crate (pure Rust), binary ones
//! by pelage's checked crate reader (`usdc::read`) into openusd's layer
//! type. Only the file's own layer is read: references, payloads and
//! sublayers are not followed. Animated attributes are read at their first
//! time sample (the first frame). Widths are read as
//! `vertex` (or `varying` on linear curves), `uniform` or `constant`;
//! curves without widths get [`DEFAULT_WIDTH`].

use super::read_error::{CurvesReadError, CurvesReadErrorKind as Kind};
use crate::Curves;
use crate::mesh::Location;
use glam::{DMat4, DVec3};
use openusd::sdf::{self, AbstractData, SpecType, Value};
use std::path::Path;

/// Width given to curves whose file has no widths.
pub const DEFAULT_WIDTH: f32 = 0.01;

/// Reads every `BasisCurves` prim of a usda or usdc file into one
/// [`Curves`] (points in world space).
pub fn read_usd_curves(path: &Path) -> Result<Curves, CurvesReadError> {
    let data = open_layer(path)?;
    let data = data.as_ref();
    let mut prims: Vec<sdf::Path> = data
        .spec_paths()
        .into_iter()
        .filter(|p| data.spec_type(p) == Some(SpecType::Prim))
        .filter(|p| token(data, p, "typeName").as_deref() == Some("BasisCurves"))
        .collect();
    prims.sort_by(|a, b| a.as_str().cmp(b.as_str()));
    if prims.is_empty() {
        return Err(CurvesReadError::whole(
            path,
            Kind::Empty(" (no BasisCurves prim)"),
        ));
    }
    let mut parts = Vec::with_capacity(prims.len());
    for prim in &prims {
        let fail = |kind| CurvesReadError::whole(path, kind);
        let at = |what: &str| format!("{}: {what}", prim.as_str());
        let counts: Vec<i32> = match attribute(data, prim, "curveVertexCounts") {
            Some(Value::IntVec(v)) => v,
            Some(_) => {
                return Err(fail(Kind::Unsupported(at(
                    "curveVertexCounts is not int[]",
                ))));
            }
            None => return Err(fail(Kind::Inconsistent(at("no curveVertexCounts")))),
        };
        let prim_points = match attribute(data, prim, "points") {
            Some(Value::Vec3fVec(v)) => v
                .iter()
                .map(|p| DVec3::new(p.x.into(), p.y.into(), p.z.into()))
                .collect(),
            Some(Value::Vec3dVec(v)) => v
                .iter()
                .map(|p| DVec3::new(p.x, p.y, p.z))
                .collect::<Vec<_>>(),
            Some(_) => {
                return Err(fail(Kind::Unsupported(at(
                    "points are neither float3[] nor double3[]",
                ))));
            }
            None => return Err(fail(Kind::Inconsistent(at("no points")))),
        };
        if let Some(i) = counts.iter().position(|&c| c < 1) {
            return Err(fail(Kind::Inconsistent(at(&format!(
                "curveVertexCounts[{i}] is {}",
                counts[i]
            )))));
        }
        let total: i64 = counts.iter().map(|&c| c as i64).sum();
        if total != prim_points.len() as i64 {
            return Err(fail(Kind::Inconsistent(at(&format!(
                "curveVertexCounts add up to {total} but there are {} points",
                prim_points.len()
            )))));
        }
        let transform = world_transform(data, prim).map_err(|m| fail(Kind::Unsupported(at(&m))))?;
        let prim_widths =
            read_widths(data, prim, &counts).map_err(|m| fail(Kind::Inconsistent(at(&m))))?;
        let points = prim_points
            .iter()
            .map(|&p| transform.transform_point3(p).as_vec3())
            .collect();
        let offsets = std::iter::once(0)
            .chain(counts.iter().scan(0u32, |end, &c| {
                *end += c as u32;
                Some(*end)
            }))
            .collect();
        let curves = Curves::new(points, prim_widths, offsets)
            .map_err(|e| CurvesReadError::whole(path, e.into()))?;
        let curves = with_primvars(curves, data, prim, transform)
            .map_err(|e| fail(Kind::Inconsistent(at(&e.to_string()))))?;
        parts.push(curves);
    }
    super::join(&parts).map_err(|e| CurvesReadError::whole(path, e.into()))
}

/// Adds the attributes pelage writes, where the prim has them with the
/// interpolation pelage writes them with (others are left out): normals,
/// `displayColor` and `displayOpacity` per point, `st` and `hair_id` per
/// curve. Normals are turned with the prim's transform.
fn with_primvars(
    mut curves: Curves,
    data: &dyn AbstractData,
    prim: &sdf::Path,
    transform: DMat4,
) -> Result<Curves, crate::curves::CurvesError> {
    let per = |name: &str, want: &str| {
        let interpolation = metadata_token(data, prim, name, "interpolation");
        (interpolation.as_deref() == Some(want))
            .then(|| attribute(data, prim, name))
            .flatten()
    };
    if let Some(Value::Vec3fVec(v)) = per("normals", "vertex") {
        let turn = (transform != DMat4::IDENTITY).then(|| transform.inverse().transpose());
        let normals = v
            .iter()
            .map(|n| {
                let n = glam::Vec3::new(n.x, n.y, n.z);
                match turn {
                    None => n,
                    Some(m) => m
                        .transform_vector3(n.as_dvec3())
                        .as_vec3()
                        .normalize_or_zero(),
                }
            })
            .collect();
        curves = curves.with_normals(normals)?;
    }
    if let Some(Value::Vec3fVec(v)) = per("primvars:displayColor", "vertex") {
        let colors = v.iter().map(|c| glam::Vec3::new(c.x, c.y, c.z)).collect();
        curves = curves.with_colors(colors)?;
    }
    if let Some(Value::FloatVec(v)) = per("primvars:displayOpacity", "vertex") {
        curves = curves.with_opacities(v)?;
    }
    if let Some(Value::Vec2fVec(v)) = per("primvars:st", "uniform") {
        let uvs = v.iter().map(|t| glam::Vec2::new(t.x, t.y)).collect();
        curves = curves.with_root_uvs(uvs)?;
    }
    let ids: Option<Vec<u64>> = match per("primvars:hair_id", "uniform") {
        Some(Value::IntVec(v)) => v.iter().map(|&i| u64::try_from(i).ok()).collect(),
        Some(Value::Int64Vec(v)) => v.iter().map(|&i| u64::try_from(i).ok()).collect(),
        _ => None,
    };
    if let Some(ids) = ids {
        curves = curves.with_ids(ids)?;
    }
    Ok(curves)
}

/// The union of the authored `extent` of every `BasisCurves` prim of a
/// usda or usdc file (`None` when no prim has one), without reading the
/// curves: what an assembly layer needs from its part files.
pub fn read_usd_extent(path: &Path) -> Result<Option<(glam::Vec3, glam::Vec3)>, CurvesReadError> {
    let data = open_layer(path)?;
    let data = data.as_ref();
    let mut bounds: Option<(glam::Vec3, glam::Vec3)> = None;
    for prim in data.spec_paths() {
        if data.spec_type(&prim) != Some(SpecType::Prim)
            || token(data, &prim, "typeName").as_deref() != Some("BasisCurves")
        {
            continue;
        }
        if let Some(Value::Vec3fVec(e)) = attribute(data, &prim, "extent")
            && let [lo, hi] = e[..]
        {
            let (lo, hi) = (
                glam::Vec3::new(lo.x, lo.y, lo.z),
                glam::Vec3::new(hi.x, hi.y, hi.z),
            );
            bounds = Some(match bounds {
                Some((l, h)) => (l.min(lo), h.max(hi)),
                None => (lo, hi),
            });
        }
    }
    Ok(bounds)
}

/// Parses a usda or usdc layer (by its first bytes).
fn open_layer(path: &Path) -> Result<Box<dyn AbstractData>, CurvesReadError> {
    let mut head = [0u8; 8];
    let n = std::fs::File::open(path)
        .and_then(|mut f| std::io::Read::read(&mut f, &mut head))
        .map_err(|e| CurvesReadError::whole(path, Kind::Io(e)))?;
    let head = &head[..n];
    if head.starts_with(b"PXR-USDC") {
        super::usdc::read_usdc(path)
    } else if head.starts_with(b"#usda") {
        Ok(Box::new(
            openusd::usda::read_file(path).map_err(|e| parse_error(path, &e))?,
        ))
    } else {
        Err(CurvesReadError::new(
            path,
            Location::Line(1),
            Kind::Syntax("not a USD file: it starts with neither '#usda' nor 'PXR-USDC'".into()),
        ))
    }
}

/// Splits openusd's `PATH:LINE: COL: message` into a line location.
fn parse_error(path: &Path, error: &dyn std::fmt::Display) -> CurvesReadError {
    let text = format!("{error:#}");
    let shown = path.display().to_string();
    let parsed = text
        .strip_prefix(&shown)
        .and_then(|r| r.strip_prefix(':'))
        .and_then(|r| r.split_once(':'))
        .and_then(|(line, rest)| Some((line.trim().parse::<usize>().ok()?, rest.trim_start())));
    if let Some((line, rest)) = parsed {
        // openusd puts the column before the message.
        let message = match rest.split_once(": ") {
            Some((column, message)) if column.parse::<usize>().is_ok() => message,
            _ => rest,
        };
        return CurvesReadError::new(
            path,
            Location::Line(line),
            Kind::Syntax(message.to_string()),
        );
    }
    CurvesReadError::whole(path, Kind::Syntax(text))
}

/// An attribute's value: its default, or for an animated attribute with
/// no default its earliest time sample (the first frame).
fn attribute(data: &dyn AbstractData, prim: &sdf::Path, name: &str) -> Option<Value> {
    let property = prim.append_property(name).ok()?;
    let field = |f| data.try_field(&property, f).ok().flatten();
    if let Some(value) = field("default") {
        return Some(value.into_owned());
    }
    match field("timeSamples")?.into_owned() {
        Value::TimeSamples(samples) => samples
            .into_iter()
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, v)| v),
        _ => None,
    }
}

fn token(data: &dyn AbstractData, path: &sdf::Path, field: &str) -> Option<String> {
    match data.try_field(path, field).ok().flatten()?.as_ref() {
        Value::Token(t) => Some(t.as_str().to_string()),
        Value::String(s) => Some(s.clone()),
        _ => None,
    }
}

fn metadata_token(
    data: &dyn AbstractData,
    prim: &sdf::Path,
    name: &str,
    field: &str,
) -> Option<String> {
    token(data, &prim.append_property(name).ok()?, field)
}

/// Widths as one value per point, from any interpolation USD allows on
/// curves whose varying count equals the vertex count (linear, pinned).
fn read_widths(
    data: &dyn AbstractData,
    prim: &sdf::Path,
    counts: &[i32],
) -> Result<Vec<f32>, String> {
    let n_points: usize = counts.iter().map(|&c| c as usize).sum();
    let values: Vec<f32> = match attribute(data, prim, "widths") {
        None => return Ok(vec![DEFAULT_WIDTH; n_points]),
        Some(Value::FloatVec(v)) => v,
        Some(Value::DoubleVec(v)) => v.iter().map(|&w| w as f32).collect(),
        Some(Value::Float(w)) => vec![w],
        Some(_) => return Err("widths are not float[]".into()),
    };
    let interpolation =
        metadata_token(data, prim, "widths", "interpolation").unwrap_or_else(|| "vertex".into());
    match interpolation.as_str() {
        "constant" if values.len() == 1 => Ok(vec![values[0]; n_points]),
        "uniform" if values.len() == counts.len() => Ok(counts
            .iter()
            .zip(&values)
            .flat_map(|(&c, &w)| std::iter::repeat_n(w, c as usize))
            .collect()),
        "vertex" | "varying" if values.len() == n_points => Ok(values),
        _ if values.len() == 1 => Ok(vec![values[0]; n_points]),
        other => Err(format!(
            "{} widths with {other} interpolation for {} curves of {n_points} points; pelage reads constant, uniform and per-vertex widths",
            values.len(),
            counts.len()
        )),
    }
}

/// The prim's transform to world space: its own and its ancestors'
/// `xformOpOrder`, composed parent first.
fn world_transform(data: &dyn AbstractData, prim: &sdf::Path) -> Result<DMat4, String> {
    let mut chain: Vec<sdf::Path> = prim.ancestors().filter(|p| !p.is_abs_root()).collect();
    chain.sort_by_key(|p| p.as_str().len());
    let mut world = DMat4::IDENTITY;
    for path in chain {
        world *= local_transform(data, &path)?;
    }
    Ok(world)
}

fn local_transform(data: &dyn AbstractData, prim: &sdf::Path) -> Result<DMat4, String> {
    let order = match attribute(data, prim, "xformOpOrder") {
        Some(Value::TokenVec(ops)) => ops,
        _ => return Ok(DMat4::IDENTITY),
    };
    let mut local = DMat4::IDENTITY;
    for op in &order {
        let op = op.as_str();
        let unsupported = || {
            format!(
                "{}: transform op {op:?} is not supported; bake transforms on export",
                prim.as_str()
            )
        };
        let value = attribute(data, prim, op)
            .ok_or_else(|| format!("{}: {op} has no value", prim.as_str()))?;
        let kind = op.strip_prefix("xformOp:").ok_or_else(unsupported)?;
        let kind = kind.split(':').next().unwrap_or(kind);
        let m = match (kind, value) {
            // USD matrices act on row vectors; read as columns they are the
            // column-vector matrix glam uses.
            ("transform", Value::Matrix4d(m)) => DMat4::from_cols_array(&m.0),
            ("translate", v) => DMat4::from_translation(vec3(&v).ok_or_else(unsupported)?),
            ("scale", v) => DMat4::from_scale(vec3(&v).ok_or_else(unsupported)?),
            ("rotateXYZ", v) => {
                let r = vec3(&v)
                    .ok_or_else(unsupported)?
                    .to_array()
                    .map(f64::to_radians);
                DMat4::from_rotation_z(r[2])
                    * DMat4::from_rotation_y(r[1])
                    * DMat4::from_rotation_x(r[0])
            }
            _ => return Err(unsupported()),
        };
        local *= m;
    }
    Ok(local)
}

fn vec3(value: &Value) -> Option<DVec3> {
    match value {
        Value::Vec3d(v) => Some(DVec3::new(v.x, v.y, v.z)),
        Value::Vec3f(v) => Some(DVec3::new(v.x.into(), v.y.into(), v.z.into())),
        _ => None,
    }
}
