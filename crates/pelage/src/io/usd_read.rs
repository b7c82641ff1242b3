//! Curves from USD (usda or usdc): every `BasisCurves` prim of the layer,
//! in path order, concatenated, with its ancestors' transforms applied — what
//! pelage's writer and Blender's USD export write.
//!
//! Text layers are parsed by the `openusd` crate (pure Rust), binary ones
//! by pelage's checked crate reader (`usdc::read`) into openusd's layer
//! type. Only the file's own layer is read, except a layer with no curves
//! of its own whose prims reference files (pelage's farm assembly): those
//! files' curves are read, in path order. Payloads, sublayers, references
//! of a layer with curves, and transforms above a reference are not
//! followed. Animated attributes are read at their first
//! time sample (the first frame). Widths are read as
//! `vertex` (or `varying` on linear curves), `uniform` or `constant`;
//! curves without widths get [`DEFAULT_WIDTH`].

use super::read_error::{CurvesReadError, CurvesReadErrorKind as Kind};
use crate::Curves;
use crate::error::Where;
use glam::{DMat4, DVec3};
use openusd::sdf::{self, AbstractData, SpecType, Value};
use std::path::Path;

use crate::curves::DEFAULT_WIDTH;

/// Reads every `BasisCurves` prim of a usda or usdc file into one
/// [`Curves`] (points in world space).
pub fn read_usd_curves(path: &Path) -> Result<Curves, CurvesReadError> {
    read_usd_curves_at(path, None)
}

/// [`read_usd_curves`] at time code `time`: animated `points` are
/// interpolated linearly between the samples around it (held before the
/// first and after the last, as USD does); `None` reads the first sample.
/// Everything else is read as [`read_usd_curves`] reads it.
pub fn read_usd_curves_at(path: &Path, time: Option<f64>) -> Result<Curves, CurvesReadError> {
    read_usd_curves_within(path, time, 0)
}

/// How many layers deep references are followed (a farm assembly is one;
/// a loop of references stops here).
const MOST_REFERENCE_DEPTH: usize = 4;

/// [`read_usd_curves_at`] of a layer `depth` references below the file
/// asked for.
fn read_usd_curves_within(
    path: &Path,
    time: Option<f64>,
    depth: usize,
) -> Result<Curves, CurvesReadError> {
    let data = open_layer_with(path, time.is_some())?;
    let data = data.as_ref();
    if !curve_prims(data).is_empty() {
        return curves_from_layer(path, data, time);
    }
    let files = referenced_files(path, data);
    if files.is_empty() || depth >= MOST_REFERENCE_DEPTH {
        return curves_from_layer(path, data, time);
    }
    let mut parts = Vec::with_capacity(files.len());
    for file in &files {
        if !file.exists() {
            return Err(CurvesReadError::whole(
                path,
                Kind::Inconsistent(format!(
                    "it references {}, which is not there",
                    file.display()
                )),
            ));
        }
        parts.push(read_usd_curves_within(file, time, depth + 1)?);
    }
    crate::curves::join(parts.iter())
        .map_err(|e| CurvesReadError::whole(path, Kind::Inconsistent(e.to_string())))
}

/// The files `data`'s prims reference (`references` with an asset path),
/// in prim path order, relative to `path`'s folder: a farm assembly's part
/// files.
fn referenced_files(path: &Path, data: &dyn AbstractData) -> Vec<std::path::PathBuf> {
    let folder = crate::io::folder_of(path);
    let mut prims: Vec<sdf::Path> = data
        .spec_paths()
        .into_iter()
        .filter(|p| data.spec_type(p) == Some(SpecType::Prim))
        .collect();
    prims.sort_by(|a, b| a.as_str().cmp(b.as_str()));
    let mut files = Vec::new();
    for prim in &prims {
        if let Ok(Some(value)) = data.try_field(prim, "references")
            && let Value::ReferenceListOp(list) = value.as_ref()
        {
            files.extend(
                list.iter()
                    .filter(|r| !r.asset_path.is_empty())
                    .map(|r| folder.join(&r.asset_path)),
            );
        }
    }
    files
}

/// [`read_usd_curves`] of a usda or usdc file's bytes held in memory (a
/// network buffer, a fuzzer's input); `path` is what errors call it.
pub fn usd_curves_from_bytes(bytes: &[u8], path: &Path) -> Result<Curves, CurvesReadError> {
    let data = layer_from_bytes(bytes, path, false)?;
    curves_from_layer(path, data.as_ref(), None)
}

/// A USD file's curves over time, parsed once with every time sample, for
/// reading many frames (`pelage render --frames`).
pub struct UsdCurvesSequence {
    path: std::path::PathBuf,
    layer: Box<dyn AbstractData>,
}

impl UsdCurvesSequence {
    /// Parses the file at `path`.
    pub fn open(path: &Path) -> Result<Self, CurvesReadError> {
        // An input of this run: no writer may replace it.
        crate::io::check_input(path, "a USD file (.usd, .usda, .usdc)")
            .map_err(|e| CurvesReadError::whole(path, Kind::Io(e)))?;
        Ok(Self {
            path: path.to_path_buf(),
            layer: open_layer_with(path, true)?,
        })
    }

    /// The curves at time code `time`, as [`read_usd_curves_at`] reads them.
    pub fn at(&self, time: f64) -> Result<Curves, CurvesReadError> {
        curves_from_layer(&self.path, self.layer.as_ref(), Some(time))
    }

    /// The curves at their first sample, as [`read_usd_curves`] reads
    /// them; `None` for a layer that holds no curves itself (a farm
    /// assembly, whose references [`read_usd_curves`] follows).
    pub fn first(&self) -> Option<Result<Curves, CurvesReadError>> {
        let data = self.layer.as_ref();
        (!curve_prims(data).is_empty()).then(|| curves_from_layer(&self.path, data, None))
    }

    /// The time codes at which any curves' points are sampled, ascending
    /// (empty for still curves).
    pub fn times(&self) -> Vec<f64> {
        let data = self.layer.as_ref();
        let mut times: Vec<f64> = curve_prims(data)
            .iter()
            .flat_map(|p| sample_times(data, p, "points"))
            .collect();
        times.sort_by(f64::total_cmp);
        times.dedup();
        times
    }
}

/// The layer's `BasisCurves` prims, in path order.
fn curve_prims(data: &dyn AbstractData) -> Vec<sdf::Path> {
    let mut prims: Vec<sdf::Path> = data
        .spec_paths()
        .into_iter()
        .filter(|p| data.spec_type(p) == Some(SpecType::Prim))
        .filter(|p| token(data, p, "typeName").as_deref() == Some("BasisCurves"))
        .collect();
    prims.sort_by(|a, b| a.as_str().cmp(b.as_str()));
    prims
}

fn curves_from_layer(
    path: &Path,
    data: &dyn AbstractData,
    time: Option<f64>,
) -> Result<Curves, CurvesReadError> {
    let prims = curve_prims(data);
    if prims.is_empty() {
        return Err(CurvesReadError::whole(
            path,
            Kind::Empty(" (no BasisCurves prim)"),
        ));
    }
    let mut parts = Vec::with_capacity(prims.len());
    let mut guides = Vec::new();
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
        let points_value = match time {
            Some(t) => attribute_at(data, prim, "points", t),
            None => attribute(data, prim, "points"),
        };
        let prim_points = match points_value {
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
        let curves = with_primvars(curves, data, prim, transform).map_err(|error| {
            fail(Kind::CurvesOf {
                object: prim.as_str().to_string(),
                error,
            })
        })?;
        let guide =
            matches!(attribute(data, prim, "purpose"), Some(Value::Token(t)) if t == "guide");
        match guide {
            true => guides.push(curves),
            false => parts.push(curves),
        }
    }
    // Guides (`purpose = "guide"`) are not hairs: read them only from a
    // file that holds nothing else (a guides file).
    let read = if parts.is_empty() { &guides } else { &parts };
    crate::curves::join(read).map_err(|e| CurvesReadError::whole(path, e.into()))
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
    if let Some(Value::IntVec(v)) = per("primvars:hair_region", "uniform") {
        let regions: Option<Vec<u32>> = v.iter().map(|&r| u32::try_from(r).ok()).collect();
        if let Some(regions) = regions {
            curves = curves.with_regions(regions)?;
        }
    }
    // Hair-shading values only where all of them are there, as pelage
    // writes them.
    let float = |name: &str| match per(&format!("primvars:{name}"), "uniform") {
        Some(Value::FloatVec(v)) => Some(v),
        _ => None,
    };
    let tint_name = format!("primvars:{}", crate::curves::HairShading::TINT);
    let tint = match per(&tint_name, "uniform") {
        Some(Value::Vec3fVec(v)) => {
            Some(v.iter().map(|c| glam::Vec3::new(c.x, c.y, c.z)).collect())
        }
        _ => None,
    };
    let found = crate::curves::HairShading::FLOAT_NAMES.map(float);
    if let Some(shading) = crate::curves::HairShading::from_found(found, tint) {
        curves = curves.with_shading(shading)?;
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

/// What a USD layer says about itself: its stage metadata and the prims
/// under its default prim (for stitching frame files with value clips).
#[derive(Debug, Clone, PartialEq)]
pub struct UsdLayerInfo {
    /// The default prim's name.
    pub default_prim: String,
    /// The default prim's children, in order.
    pub children: Vec<String>,
    /// `metersPerUnit` (1 when not authored).
    pub meters_per_unit: f64,
    /// `upAxis` (`Y` when not authored).
    pub up_axis: String,
    /// `timeCodesPerSecond` (24 when not authored).
    pub time_codes_per_second: f64,
    /// `startTimeCode` and `endTimeCode`, when authored.
    pub time_range: Option<(f64, f64)>,
    /// The layer's `documentation` string, when authored.
    pub documentation: Option<String>,
}

/// Reads a layer's [`UsdLayerInfo`].
pub fn read_usd_layer_info(path: &Path) -> Result<UsdLayerInfo, CurvesReadError> {
    let layer = open_layer(path)?;
    let data = layer.as_ref();
    let root = sdf::Path::abs_root();
    let field = |name: &str| {
        data.try_field(&root, name)
            .ok()
            .flatten()
            .map(|v| v.into_owned())
    };
    let number = |name: &str| match field(name) {
        Some(Value::Double(d)) => Some(d),
        Some(Value::Float(f)) => Some(f64::from(f)),
        Some(Value::Int(i)) => Some(f64::from(i)),
        _ => None,
    };
    let default_prim = token(data, &root, "defaultPrim").ok_or_else(|| {
        CurvesReadError::whole(
            path,
            Kind::Inconsistent("the layer has no defaultPrim".into()),
        )
    })?;
    let prim = sdf::Path::new(&format!("/{default_prim}"))
        .map_err(|e| CurvesReadError::whole(path, Kind::Inconsistent(e.to_string())))?;
    let children = match data
        .try_field(&prim, "primChildren")
        .ok()
        .flatten()
        .as_deref()
    {
        Some(Value::TokenVec(names)) => names.iter().map(|t| t.as_str().to_string()).collect(),
        _ => Vec::new(),
    };
    Ok(UsdLayerInfo {
        default_prim,
        children,
        meters_per_unit: number("metersPerUnit").unwrap_or(1.0),
        up_axis: token(data, &root, "upAxis").unwrap_or_else(|| "Y".into()),
        time_codes_per_second: number("timeCodesPerSecond").unwrap_or(24.0),
        time_range: number("startTimeCode").zip(number("endTimeCode")),
        documentation: match field("documentation") {
            Some(Value::String(text)) => Some(text),
            _ => None,
        },
    })
}

/// Parses a usda or usdc layer (by its first bytes), with only the first
/// time sample of animated values (binary layers).
fn open_layer(path: &Path) -> Result<Box<dyn AbstractData>, CurvesReadError> {
    open_layer_with(path, false)
}

/// Parses a usda or usdc layer; `all_samples`: keep every time sample.
fn open_layer_with(
    path: &Path,
    all_samples: bool,
) -> Result<Box<dyn AbstractData>, CurvesReadError> {
    let mut head = [0u8; 8];
    let n = std::fs::File::open(path)
        .and_then(|mut f| std::io::Read::read(&mut f, &mut head))
        .map_err(|e| CurvesReadError::whole(path, Kind::Io(e)))?;
    let head = &head[..n];
    if head.starts_with(b"PXR-USDC") {
        super::usdc::read_usdc(path, all_samples)
    } else if head.starts_with(b"#usda") {
        Ok(Box::new(
            openusd::usda::read_file(path).map_err(|e| parse_error(path, &e))?,
        ))
    } else {
        Err(CurvesReadError::new(
            path,
            Where::line(1),
            Kind::Syntax("not a USD file: it starts with neither '#usda' nor 'PXR-USDC'".into()),
        ))
    }
}

/// A usda or usdc layer (by its first bytes) from bytes in memory.
fn layer_from_bytes(
    bytes: &[u8],
    path: &Path,
    all_samples: bool,
) -> Result<Box<dyn AbstractData>, CurvesReadError> {
    if bytes.starts_with(b"PXR-USDC") {
        super::usdc::read_usdc_bytes(bytes, path, all_samples)
    } else if bytes.starts_with(b"#usda") {
        let text = std::str::from_utf8(bytes).map_err(|e| {
            CurvesReadError::whole(path, Kind::Syntax(format!("not UTF-8 text: {e}")))
        })?;
        let data = openusd::usda::parse(text).map_err(|e| parse_error(path, &e))?;
        Ok(Box::new(data))
    } else {
        Err(CurvesReadError::new(
            path,
            Where::line(1),
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
        return CurvesReadError::new(path, Where::line(line), Kind::Syntax(message.to_string()));
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

/// An attribute's value at time code `time`: its time samples
/// interpolated (linearly for float vector arrays of equal length, held
/// otherwise), or its default when it has no samples.
fn attribute_at(data: &dyn AbstractData, prim: &sdf::Path, name: &str, time: f64) -> Option<Value> {
    let property = prim.append_property(name).ok()?;
    let field = |f| data.try_field(&property, f).ok().flatten();
    let mut samples = match field("timeSamples").map(|v| v.into_owned()) {
        Some(Value::TimeSamples(samples)) if !samples.is_empty() => samples,
        _ => return field("default").map(|v| v.into_owned()),
    };
    samples.sort_by(|a, b| a.0.total_cmp(&b.0));
    let after = samples.partition_point(|(t, _)| *t <= time);
    if after == 0 {
        return Some(samples.swap_remove(0).1);
    }
    if after == samples.len() {
        return samples.pop().map(|(_, v)| v);
    }
    let (t1, v1) = samples.swap_remove(after);
    let (t0, v0) = samples.swap_remove(after - 1);
    let s = if t1 > t0 {
        (time - t0) / (t1 - t0)
    } else {
        0.0
    };
    Some(match (v0, v1) {
        (Value::Vec3fVec(a), Value::Vec3fVec(b)) if a.len() == b.len() => Value::Vec3fVec(
            a.iter()
                .zip(&b)
                .map(|(p, q)| {
                    let s = s as f32;
                    openusd::gf::Vec3f {
                        x: p.x + s * (q.x - p.x),
                        y: p.y + s * (q.y - p.y),
                        z: p.z + s * (q.z - p.z),
                    }
                })
                .collect(),
        ),
        (Value::Vec3dVec(a), Value::Vec3dVec(b)) if a.len() == b.len() => Value::Vec3dVec(
            a.iter()
                .zip(&b)
                .map(|(p, q)| openusd::gf::Vec3d {
                    x: p.x + s * (q.x - p.x),
                    y: p.y + s * (q.y - p.y),
                    z: p.z + s * (q.z - p.z),
                })
                .collect(),
        ),
        (v0, _) => v0,
    })
}

/// The time codes at which an attribute is sampled (empty when it has
/// none).
fn sample_times(data: &dyn AbstractData, prim: &sdf::Path, name: &str) -> Vec<f64> {
    let Ok(property) = prim.append_property(name) else {
        return Vec::new();
    };
    match data
        .try_field(&property, "timeSamples")
        .ok()
        .flatten()
        .as_deref()
    {
        Some(Value::TimeSamples(samples)) => samples.iter().map(|(t, _)| *t).collect(),
        _ => Vec::new(),
    }
}

/// Every `Mesh` prim of a USD layer, merged (in path order, in world
/// space), with its animation: [`read_usd_skin`].
pub(crate) struct UsdSkin {
    /// Positions at the first sample (or the default).
    pub positions: Vec<glam::Vec3>,
    /// Faces fan-triangulated.
    pub triangles: Vec<[u32; 3]>,
    /// `primvars:st` (or the first `texCoord2f[]` primvar), per face
    /// corner or per vertex.
    pub uvs: Option<crate::mesh::Uvs>,
    /// Each time code at which some prim's points are sampled, ascending.
    pub times: Vec<f64>,
    /// Per prim: its points' samples (time, world-space points), or one
    /// sample at time 0 for a prim that does not move.
    prims: Vec<Vec<(f64, Vec<glam::Vec3>)>>,
}

impl UsdSkin {
    /// The merged vertex positions at time code `time`: each prim's
    /// samples interpolated linearly (held before the first and after the
    /// last).
    pub(crate) fn positions_at(&self, time: f64) -> Result<Vec<glam::Vec3>, String> {
        let mut out = Vec::with_capacity(self.positions.len());
        for samples in &self.prims {
            let after = samples.partition_point(|(t, _)| *t <= time);
            let points: Vec<glam::Vec3> = match after {
                0 => samples[0].1.clone(),
                n if n == samples.len() => samples[n - 1].1.clone(),
                n => {
                    let ((t0, a), (t1, b)) = (&samples[n - 1], &samples[n]);
                    if a.len() != b.len() {
                        return Err(format!(
                            "the points change count between times {t0} and {t1}: the topology must not change over time"
                        ));
                    }
                    let s = ((time - t0) / (t1 - t0)) as f32;
                    a.iter().zip(b).map(|(p, q)| p.lerp(*q, s)).collect()
                }
            };
            out.extend(points);
        }
        if out.len() != self.positions.len() {
            return Err(format!(
                "at time {time} the meshes have {} points, not {}: the topology must not change over time",
                out.len(),
                self.positions.len()
            ));
        }
        Ok(out)
    }
}

fn vec3_array(value: Option<Value>) -> Result<Vec<DVec3>, String> {
    match value {
        Some(Value::Vec3fVec(v)) => Ok(v
            .iter()
            .map(|p| DVec3::new(p.x.into(), p.y.into(), p.z.into()))
            .collect()),
        Some(Value::Vec3dVec(v)) => Ok(v.iter().map(|p| DVec3::new(p.x, p.y, p.z)).collect()),
        Some(_) => Err("points are neither float3[] nor double3[]".into()),
        None => Err("no points".into()),
    }
}

/// Reads the `Mesh` prims of a usda or usdc file as one skin, keeping
/// every time sample of their points.
pub(crate) fn read_usd_skin(path: &Path) -> Result<UsdSkin, CurvesReadError> {
    skin_from_layer(path, open_layer_with(path, true)?.as_ref())
}

/// [`read_usd_skin`] of a file's bytes (`path` names it in errors).
pub(crate) fn usd_skin_from_bytes(bytes: &[u8], path: &Path) -> Result<UsdSkin, CurvesReadError> {
    skin_from_layer(path, layer_from_bytes(bytes, path, true)?.as_ref())
}

fn skin_from_layer(path: &Path, data: &dyn AbstractData) -> Result<UsdSkin, CurvesReadError> {
    let mut prim_paths: Vec<sdf::Path> = data
        .spec_paths()
        .into_iter()
        .filter(|p| data.spec_type(p) == Some(SpecType::Prim))
        .filter(|p| token(data, p, "typeName").as_deref() == Some("Mesh"))
        .collect();
    prim_paths.sort_by(|a, b| a.as_str().cmp(b.as_str()));
    if prim_paths.is_empty() {
        return Err(CurvesReadError::whole(
            path,
            Kind::Syntax("the file has no Mesh prim".into()),
        ));
    }
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let (mut uv_values, mut uv_triangles) = (Vec::new(), Vec::new());
    // UVs count only when every prim has them.
    let mut all_have_uvs = true;
    let mut times = Vec::new();
    let mut prims = Vec::new();
    for prim in prim_paths {
        let fail = |m: String| {
            CurvesReadError::whole(path, Kind::Inconsistent(format!("{}: {m}", prim.as_str())))
        };
        let transform = world_transform(data, &prim).map_err(fail)?;
        let world = |points: Vec<DVec3>| -> Vec<glam::Vec3> {
            points
                .iter()
                .map(|&p| transform.transform_point3(p).as_vec3())
                .collect()
        };
        let mut prim_times = sample_times(data, &prim, "points");
        prim_times.sort_by(f64::total_cmp);
        prim_times.dedup();
        let mut samples = Vec::with_capacity(prim_times.len().max(1));
        for &t in &prim_times {
            let points = vec3_array(attribute_at(data, &prim, "points", t)).map_err(fail)?;
            samples.push((t, world(points)));
        }
        if samples.is_empty() {
            let points = vec3_array(attribute(data, &prim, "points")).map_err(fail)?;
            samples.push((0.0, world(points)));
        }
        times.extend(prim_times);
        let points = samples[0].1.clone();
        let ints = |name: &str| match attribute(data, &prim, name) {
            Some(Value::IntVec(v)) => Ok(v),
            Some(_) => Err(fail(format!("{name} is not int[]"))),
            None => Err(fail(format!("no {name}"))),
        };
        let counts = ints("faceVertexCounts")?;
        let indices = ints("faceVertexIndices")?;
        let base = positions.len() as u32;
        let (prim_triangles, prim_corners) =
            prim_faces(&counts, &indices, points.len(), base).map_err(fail)?;
        let has_uvs = prim_uvs(
            data,
            &prim,
            &prim_triangles,
            &prim_corners,
            base,
            points.len(),
        )
        .map_err(fail)?
        .map(|(values, triangles)| {
            let start = uv_values.len() as u32;
            uv_triangles.extend(triangles.into_iter().map(|t| t.map(|i| start + i)));
            uv_values.extend(values);
        })
        .is_some();
        all_have_uvs &= has_uvs;
        positions.extend_from_slice(&points);
        triangles.extend(prim_triangles);
        prims.push(samples);
    }
    times.sort_by(f64::total_cmp);
    times.dedup();
    let uvs = all_have_uvs.then_some(crate::mesh::Uvs::PerCorner {
        values: uv_values,
        indices: uv_triangles,
    });
    Ok(UsdSkin {
        positions,
        triangles,
        uvs,
        times,
        prims,
    })
}

/// A prim's triangles (point indices) and each one's face-corner indices.
type PrimFaces = (Vec<[u32; 3]>, Vec<[usize; 3]>);

/// A prim's UV values and each triangle's indices into them.
type PrimUvs = (Vec<glam::Vec2>, Vec<[u32; 3]>);

/// A `Mesh` prim's faces fan triangulated (point indices offset by
/// `base`), with the face-corner indices of each triangle's corners;
/// an error says which face is malformed.
fn prim_faces(
    counts: &[i32],
    indices: &[i32],
    points: usize,
    base: u32,
) -> Result<PrimFaces, String> {
    let mut corner = 0usize;
    let mut prim_triangles = Vec::new();
    let mut prim_corners = Vec::new();
    for (f, &c) in counts.iter().enumerate() {
        if c < 3 {
            return Err(format!("face {f} has {c} vertices"));
        }
        let c = c as usize;
        let face = indices
            .get(corner..corner + c)
            .ok_or_else(|| format!("faceVertexIndices end inside face {f}"))?;
        for (k, &i) in face.iter().enumerate() {
            if i < 0 || i as usize >= points {
                return Err(format!("face {f} corner {k} names point {i} of {points}"));
            }
        }
        for k in 1..c - 1 {
            prim_triangles.push([face[0], face[k], face[k + 1]].map(|i| base + i as u32));
            prim_corners.push([corner, corner + k, corner + k + 1]);
        }
        corner += c;
    }
    if corner != indices.len() {
        return Err(format!(
            "faceVertexCounts add up to {corner} but there are {} indices",
            indices.len()
        ));
    }
    Ok((prim_triangles, prim_corners))
}

/// A `Mesh` prim's UVs, faceVarying (optionally indexed) or vertex: the
/// values and each triangle's indices into them (from 0), or `None` when
/// the prim has none pelage reads.
fn prim_uvs(
    data: &dyn AbstractData,
    prim: &sdf::Path,
    prim_triangles: &[[u32; 3]],
    prim_corners: &[[usize; 3]],
    base: u32,
    points: usize,
) -> Result<Option<PrimUvs>, String> {
    let st = ["primvars:st", "primvars:UVMap", "primvars:uv"]
        .into_iter()
        .find_map(|name| {
            let value = attribute(data, prim, name)?;
            let values: Vec<glam::Vec2> = match value {
                Value::Vec2fVec(v) => v.iter().map(|t| glam::Vec2::new(t.x, t.y)).collect(),
                _ => return None,
            };
            let interpolation = metadata_token(data, prim, name, "interpolation");
            let indices = match attribute(data, prim, &format!("{name}:indices")) {
                Some(Value::IntVec(v)) => Some(v),
                _ => None,
            };
            Some((values, interpolation, indices))
        });
    let Some((values, interpolation, st_indices)) = st else {
        return Ok(None);
    };
    let lookup = |k: usize| -> Option<u32> {
        let i = match &st_indices {
            Some(ix) => usize::try_from(*ix.get(k)?).ok()?,
            None => k,
        };
        (i < values.len()).then_some(i as u32)
    };
    let triangles = match interpolation.as_deref() {
        Some("faceVarying") => {
            let mut triangles = Vec::with_capacity(prim_corners.len());
            for corners in prim_corners {
                let [Some(a), Some(b), Some(c)] = corners.map(lookup) else {
                    return Err("primvars:st has too few values".into());
                };
                triangles.push([a, b, c]);
            }
            triangles
        }
        Some("vertex") | Some("varying") if values.len() == points => {
            prim_triangles.iter().map(|t| t.map(|i| i - base)).collect()
        }
        _ => return Ok(None),
    };
    Ok(Some((values, triangles)))
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
    // A path has one ancestor a `/`. openusd's walk up a malformed name
    // (a `}` in it, say) never reaches the root: bound it.
    let depth = prim.as_str().matches('/').count() + 1;
    let mut chain: Vec<sdf::Path> = prim
        .ancestors()
        .take(depth + 1)
        .filter(|p| !p.is_abs_root())
        .collect();
    if chain.len() > depth {
        return Err("not a valid prim path (its ancestors never reach the root)".into());
    }
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
