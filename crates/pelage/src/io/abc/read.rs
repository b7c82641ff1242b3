//! Curves from Alembic (Ogawa): every `ICurves` object of the archive, in
//! file order, joined — what pelage's writer, Blender and Houdini write.
//! Positions, vertex counts and widths come from the curves schema;
//! normals (`N`), and the arbitrary parameters `groom_color`,
//! `groom_opacity`, `groom_id`, `groom_root_uv` and the hair-shading values, where present with
//! pelage's layout. Each
//! property's first sample is read (the first frame of an animation).
//! Transforms of parent `Xform` objects are not applied: pelage reads
//! curves in the space they were written in.
//!
//! Every offset, count and size in the file is checked against the file
//! before it is used, so a truncated or hostile file is an error naming
//! the byte and the structure, never a panic or an allocation of a size
//! the file claims but does not hold. Groups and blocks may be shared, so
//! what is decoded from them (headers, values) is charged to one
//! [`DecodeBudget`] for the read; names and paths have length ceilings
//! ([`MAX_NAME_BYTES`], [`MAX_PATH_BYTES`]).

use super::super::read_error::{
    CurvesReadError, CurvesReadErrorKind as Kind, DecodeBudget, excerpt,
};
use super::ogawa::{Child, EMPTY_DATA};
use crate::Curves;
use crate::curves::DEFAULT_WIDTH;
use crate::curves::HairShading;
use crate::error::Where;
use crate::limits::{MAX_NAME_BYTES, MAX_PATH_BYTES};
use glam::{DMat4, DVec3, Vec2, Vec3};
use std::cell::Cell;
use std::path::Path;

/// Groups visited at most: a file whose groups share children (or list
/// an ancestor) could otherwise make the walk exponential or endless.
const MAX_GROUPS_VISITED: usize = 1 << 20;
/// Object nesting read at most.
const MAX_DEPTH: usize = 256;

/// The bytes of an Ogawa file, read with every position checked.
struct Ogawa<'a> {
    bytes: &'a [u8],
    path: &'a Path,
    visited: Cell<usize>,
    budget: DecodeBudget,
}

impl<'a> Ogawa<'a> {
    fn fail(&self, at: u64, message: String) -> CurvesReadError {
        self.refuse(at, Kind::Inconsistent(message))
    }

    /// The arrays of object `object` (at byte `at`) that do not make
    /// curves, kept typed.
    fn curves_of(
        &self,
        at: u64,
        object: &str,
        error: crate::curves::CurvesError,
    ) -> CurvesReadError {
        self.refuse(
            at,
            Kind::CurvesOf {
                object: object.to_string(),
                error,
            },
        )
    }

    /// An error of `kind` at byte `at`.
    fn refuse(&self, at: u64, kind: Kind) -> CurvesReadError {
        CurvesReadError::new(self.path, Where::element("byte", at as usize), kind)
    }

    /// Takes `bytes` of decoded values from the read's budget.
    fn charge(&self, at: u64, bytes: u64, what: &str) -> Result<(), CurvesReadError> {
        self.budget
            .charge(bytes)
            .map_err(|e| self.fail(at, format!("{what}: {e}")))
    }

    /// A name read from the file, within [`MAX_NAME_BYTES`].
    fn check_name(&self, at: u64, name: &str, what: &str) -> Result<(), CurvesReadError> {
        if name.len() > MAX_NAME_BYTES {
            return Err(self.fail(
                at,
                format!(
                    "{what}: the name {} is longer than pelage's limit of {MAX_NAME_BYTES} bytes (docs/limits.md)",
                    excerpt(name)
                ),
            ));
        }
        Ok(())
    }

    /// The root group, after checking the header.
    fn open(bytes: &'a [u8], path: &'a Path) -> Result<(Self, Child), CurvesReadError> {
        let file = Self {
            bytes,
            path,
            visited: Cell::new(0),
            budget: DecodeBudget::for_file(bytes.len()),
        };
        if bytes.len() < 16 || &bytes[..5] != b"Ogawa" {
            return Err(CurvesReadError::whole(
                path,
                Kind::Syntax(
                    "not an Alembic file: it does not start with 'Ogawa' (HDF5 Alembic files are not read; re-export as Ogawa)"
                        .into(),
                ),
            ));
        }
        if bytes[5] != 0xff {
            return Err(file.fail(
                5,
                "the file was not completely written (its writer stopped before closing it)".into(),
            ));
        }
        if bytes[6..8] != [0, 1] {
            return Err(file.fail(
                6,
                format!("Ogawa version {}.{} (pelage reads 0.1)", bytes[6], bytes[7]),
            ));
        }
        let root = u64::from_le_bytes(bytes[8..16].try_into().expect("8 bytes"));
        Ok((file, root))
    }

    fn u64_at(&self, at: u64, what: &str) -> Result<u64, CurvesReadError> {
        let start = usize::try_from(at)
            .ok()
            .filter(|&s| s.checked_add(8).is_some_and(|e| e <= self.bytes.len()));
        match start {
            Some(s) => Ok(u64::from_le_bytes(
                self.bytes[s..s + 8].try_into().expect("8 bytes"),
            )),
            None => Err(self.fail(
                at,
                format!(
                    "{what} lies past the end of the file ({} bytes)",
                    self.bytes.len()
                ),
            )),
        }
    }

    /// A group's children.
    /// The file and its archive's six top parts (objects, metadata, time
    /// samplings, indexed metadata, …), checked to be six.
    fn archive(bytes: &'a [u8], path: &'a Path) -> Result<(Self, Vec<Child>), CurvesReadError> {
        let (file, root) = Self::open(bytes, path)?;
        let top = file.group(root, "the archive")?;
        if top.len() < 6 {
            return Err(file.fail(
                root,
                format!("the archive has {} parts; Alembic has 6", top.len()),
            ));
        }
        Ok((file, top))
    }

    fn group(&self, child: Child, what: &str) -> Result<Vec<Child>, CurvesReadError> {
        if child & EMPTY_DATA != 0 {
            return Err(self.fail(
                child & !EMPTY_DATA,
                format!("{what}: a data block where a group belongs"),
            ));
        }
        if child == 0 {
            return Ok(Vec::new());
        }
        let n = self.visited.get() + 1;
        if n > MAX_GROUPS_VISITED {
            return Err(self.fail(
                child,
                format!(
                    "{what}: more than {MAX_GROUPS_VISITED} groups (groups that share or loop)"
                ),
            ));
        }
        self.visited.set(n);
        let count = self.u64_at(child, what)?;
        let room = (self.bytes.len() as u64 - child - 8) / 8;
        if count > room {
            return Err(self.fail(child, format!("{what}: a group of {count} children, but only {room} fit in the rest of the file")));
        }
        (0..count)
            .map(|i| self.u64_at(child + 8 + 8 * i, what))
            .collect()
    }

    /// A data block's bytes.
    fn data(&self, child: Child, what: &str) -> Result<&'a [u8], CurvesReadError> {
        if child & EMPTY_DATA == 0 {
            return Err(self.fail(child, format!("{what}: a group where a data block belongs")));
        }
        let at = child & !EMPTY_DATA;
        if at == 0 {
            return Ok(&[]);
        }
        let size = self.u64_at(at, what)?;
        let room = self.bytes.len() as u64 - at - 8;
        if size > room {
            return Err(self.fail(
                at,
                format!("{what}: a block of {size} bytes, but only {room} remain in the file"),
            ));
        }
        Ok(&self.bytes[(at + 8) as usize..(at + 8 + size) as usize])
    }
}

/// A reader of little fields in a headers block.
struct Fields<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Fields<'a> {
    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        let end = self.at.checked_add(n)?;
        let s = self.bytes.get(self.at..end)?;
        self.at = end;
        Some(s)
    }

    fn sized(&mut self, hint: u32) -> Option<u32> {
        let n = [1, 2, 4][hint.min(2) as usize];
        let mut b = [0u8; 4];
        b[..n].copy_from_slice(self.take(n)?);
        Some(u32::from_le_bytes(b))
    }

    fn text(&mut self, n: u32) -> Option<String> {
        Some(String::from_utf8_lossy(self.take(n as usize)?).into_owned())
    }
}

/// What a property header says (`ReadPropertyHeaders`).
struct PropertyHeader {
    name: String,
    metadata: String,
    /// 0 compound, 1 scalar, 2 array.
    kind: u32,
    pod: u8,
    extent: u8,
    /// Samples in all, the first and last that differ from their
    /// predecessors (only those and sample 0 are stored), and the time
    /// sampling they follow.
    samples: u32,
    changed: (u32, u32),
    time_sampling: u32,
}

fn property_headers(block: &[u8], indexed: &[String]) -> Option<Vec<PropertyHeader>> {
    let mut f = Fields {
        bytes: block,
        at: 0,
    };
    let mut out = Vec::new();
    while f.at < block.len() {
        let info = u32::from_le_bytes(f.take(4)?.try_into().ok()?);
        let kind = match info & 3 {
            0 => 0,
            1 => 1,
            _ => 2,
        };
        let hint = (info >> 2) & 3;
        let (mut pod, mut extent) = (0, 0);
        let (mut samples, mut changed, mut time_sampling) = (0, (0, 0), 0);
        if kind != 0 {
            pod = ((info >> 4) & 0xf) as u8;
            extent = ((info >> 12) & 0xff) as u8;
            samples = f.sized(hint)?;
            changed = (1, samples.saturating_sub(1));
            if info & 0x200 != 0 {
                changed = (f.sized(hint)?, f.sized(hint)?);
            }
            if info & 0x100 != 0 {
                time_sampling = f.sized(hint)?;
            }
        }
        let name_size = f.sized(hint)?;
        let name = f.text(name_size)?;
        let index = ((info >> 20) & 0xff) as usize;
        let metadata = if index == 0xff {
            let size = f.sized(hint)?;
            f.text(size)?
        } else {
            indexed.get(index)?.clone()
        };
        out.push(PropertyHeader {
            name,
            metadata,
            kind,
            pod,
            extent,
            samples,
            changed,
            time_sampling,
        });
    }
    Some(out)
}

fn object_headers(block: &[u8], indexed: &[String]) -> Option<Vec<(String, String)>> {
    if block.len() <= 32 {
        return Some(Vec::new());
    }
    let body = &block[..block.len() - 32];
    let mut f = Fields { bytes: body, at: 0 };
    let mut out = Vec::new();
    while f.at < body.len() {
        let size = f.sized(2)?;
        let name = f.text(size)?;
        let index = f.take(1)?[0] as usize;
        let metadata = if index == 0xff {
            let size = f.sized(2)?;
            f.text(size)?
        } else {
            indexed.get(index)?.clone()
        };
        out.push((name, metadata));
    }
    Some(out)
}

fn metadata_value<'m>(metadata: &'m str, key: &str) -> Option<&'m str> {
    metadata.split(';').find_map(|kv| {
        kv.split_once('=')
            .filter(|(k, _)| *k == key)
            .map(|(_, v)| v)
    })
}

/// A compound property: its headers and each property's group.
struct Compound {
    properties: Vec<(PropertyHeader, Child)>,
}

impl Compound {
    fn read(
        file: &Ogawa,
        group: Child,
        indexed: &[String],
        what: &str,
    ) -> Result<Self, CurvesReadError> {
        let children = file.group(group, what)?;
        let Some((&last, groups)) = children.split_last() else {
            return Ok(Self {
                properties: Vec::new(),
            });
        };
        let block = file.data(last, &format!("{what}: property headers"))?;
        file.charge(last & !EMPTY_DATA, 2 * block.len() as u64, what)?;
        let headers = property_headers(block, indexed).ok_or_else(|| {
            file.fail(
                last & !EMPTY_DATA,
                format!("{what}: property headers end in the middle of a header"),
            )
        })?;
        for header in &headers {
            file.check_name(last & !EMPTY_DATA, &header.name, what)?;
        }
        if headers.len() > groups.len() {
            return Err(file.fail(
                group,
                format!(
                    "{what}: {} property headers for {} properties",
                    headers.len(),
                    groups.len()
                ),
            ));
        }
        Ok(Self {
            properties: headers.into_iter().zip(groups.iter().copied()).collect(),
        })
    }

    fn get(&self, name: &str) -> Option<&(PropertyHeader, Child)> {
        self.properties.iter().find(|(h, _)| h.name == name)
    }
}

/// The first sample of an array or scalar property, as values of `pod`
/// with `extent` components (4-byte components: float or int32; 8-byte:
/// int64 or double).
fn first_sample<'a>(
    file: &Ogawa<'a>,
    property: &(PropertyHeader, Child),
    what: &str,
) -> Result<&'a [u8], CurvesReadError> {
    sample(file, property, 0, what)
}

/// Sample `k` of an array or scalar property (the last one past its end).
fn sample<'a>(
    file: &Ogawa<'a>,
    (header, group): &(PropertyHeader, Child),
    k: usize,
    what: &str,
) -> Result<&'a [u8], CurvesReadError> {
    let children = file.group(*group, what)?;
    // Only sample 0 and the changed ones are stored: a sample before the
    // first change is sample 0, one after the last change is the last.
    let (first_changed, last_changed) = (header.changed.0 as usize, header.changed.1 as usize);
    let k = k.min(header.samples.saturating_sub(1) as usize);
    let stored = if k == 0 || k < first_changed || first_changed == 0 {
        0
    } else {
        k.min(last_changed) - first_changed + 1
    };
    // Arrays store (data, dimensions) a sample; scalars the data alone.
    let per_sample = if header.kind == 2 { 2 } else { 1 };
    let Some(&first) = children.get(stored * per_sample).or(children.first()) else {
        return Ok(&[]);
    };
    let block = file.data(first, what)?;
    if block.is_empty() {
        return Ok(block);
    }
    if block.len() < 16 {
        return Err(file.fail(
            first & !EMPTY_DATA,
            format!(
                "{what}: a sample of {} bytes is shorter than its 16-byte key",
                block.len()
            ),
        ));
    }
    let bytes = &block[16..];
    // Decoded into pelage's arrays, through a copy of the components.
    file.charge(first & !EMPTY_DATA, 2 * bytes.len() as u64, what)?;
    let size = pod_size(header.pod) * header.extent.max(1) as usize;
    if size == 0 || bytes.len() % size != 0 {
        return Err(file.fail(
            first & !EMPTY_DATA,
            format!(
                "{what}: {} bytes are not whole values of {size} bytes",
                bytes.len()
            ),
        ));
    }
    Ok(bytes)
}

fn pod_size(pod: u8) -> usize {
    match pod {
        0..=2 => 1,
        3 | 4 | 9 => 2,
        5 | 6 | 10 => 4,
        7 | 8 | 11 => 8,
        _ => 0,
    }
}

fn floats(bytes: &[u8]) -> impl Iterator<Item = f32> + '_ {
    bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes(b.try_into().expect("4 bytes")))
}

/// Reads every `ICurves` object of an Alembic file into one [`Curves`].
pub fn read_abc_curves(path: &Path) -> Result<Curves, CurvesReadError> {
    read_abc_curves_at(path, None)
}

/// [`read_abc_curves`] with the points of the sample at `seconds` (the
/// one whose time is nearest; held before the first and after the last);
/// everything else is read from the first sample. `None`: the first
/// sample.
pub fn read_abc_curves_at(path: &Path, seconds: Option<f64>) -> Result<Curves, CurvesReadError> {
    let bytes = std::fs::read(path).map_err(|e| CurvesReadError::whole(path, Kind::Io(e)))?;
    abc_curves_from_bytes(&bytes, path, seconds)
}

/// [`read_abc_curves_at`] of a file's bytes (`path` names it in errors).
pub fn abc_curves_from_bytes(
    bytes: &[u8],
    path: &Path,
    seconds: Option<f64>,
) -> Result<Curves, CurvesReadError> {
    let parts = abc_parts_from_bytes(bytes, path, seconds)?;
    crate::curves::join(parts.iter().map(|(_, c)| c))
        .map_err(|e| CurvesReadError::whole(path, e.into()))
}

/// A curves object of an Alembic file: its name (the last element of its
/// path), its curves, and whether it is flagged `groom_guide`.
pub type AbcCurvesObject = (String, Curves, bool);

/// Every curves object of an Alembic file apart, in file order, guides
/// (`groom_guide`) flagged: what pelage wrote as parts and guides. Their
/// first sample, as [`read_abc_curves`].
pub fn read_abc_objects(path: &Path) -> Result<Vec<AbcCurvesObject>, CurvesReadError> {
    let bytes = std::fs::read(path).map_err(|e| CurvesReadError::whole(path, Kind::Io(e)))?;
    abc_objects_from_bytes(&bytes, path, None)
}

/// The hairs of an Alembic file, object by object (the guides where it
/// holds nothing else), as [`read_abc_curves`] joins them.
fn abc_parts_from_bytes(
    bytes: &[u8],
    path: &Path,
    seconds: Option<f64>,
) -> Result<Vec<(String, Curves)>, CurvesReadError> {
    let objects = abc_objects_from_bytes(bytes, path, seconds)?;
    // Guide objects are not hairs: read them only from a file that holds
    // nothing else (a guides file).
    let only_guides = objects.iter().all(|(_, _, guide)| *guide);
    Ok(objects
        .into_iter()
        .filter(|(_, _, guide)| *guide == only_guides)
        .map(|(name, curves, _)| (name, curves))
        .collect())
}

/// The most time samples any property of the archive has (1, or 0, for a
/// still archive): whether reading it at one time leaves others out.
pub fn read_abc_sample_count(path: &Path) -> Result<usize, CurvesReadError> {
    let bytes = std::fs::read(path).map_err(|e| CurvesReadError::whole(path, Kind::Io(e)))?;
    let (file, top) = Ogawa::archive(&bytes, path)?;
    let samplings = time_samplings(file.data(top[4], "the time samplings")?).ok_or_else(|| {
        file.fail(
            top[4] & !EMPTY_DATA,
            "the time samplings are cut short".into(),
        )
    })?;
    Ok(samplings
        .iter()
        .map(|s| s.max_sample as usize)
        .max()
        .unwrap_or(0))
}

/// The archive's description (`_ai_Description` of its metadata), when
/// it has one: what a farm run's part file says of the groom that grew
/// it.
pub fn read_abc_description(path: &Path) -> Result<Option<String>, CurvesReadError> {
    let bytes = std::fs::read(path).map_err(|e| CurvesReadError::whole(path, Kind::Io(e)))?;
    let (file, top) = Ogawa::archive(&bytes, path)?;
    let metadata = String::from_utf8_lossy(file.data(top[3], "the archive's metadata")?);
    Ok(metadata_value(&metadata, "_ai_Description").map(str::to_string))
}

fn abc_objects_from_bytes(
    bytes: &[u8],
    path: &Path,
    seconds: Option<f64>,
) -> Result<Vec<AbcCurvesObject>, CurvesReadError> {
    let (file, top) = Ogawa::archive(bytes, path)?;
    let mut indexed = vec![String::new()];
    let block = file.data(top[5], "the indexed metadata")?;
    let mut f = Fields {
        bytes: block,
        at: 0,
    };
    while f.at < block.len() {
        let text = f.take(1).and_then(|n| f.text(n[0] as u32));
        indexed.push(text.ok_or_else(|| {
            file.fail(
                top[5] & !EMPTY_DATA,
                "the indexed metadata ends in the middle of an entry".into(),
            )
        })?);
    }
    let mut found = Vec::new();
    collect_curves(&file, top[2], "", &indexed, DMat4::IDENTITY, 0, &mut found)?;
    if found.is_empty() {
        return Err(CurvesReadError::whole(
            path,
            Kind::Empty(" (no ICurves object)"),
        ));
    }
    let samplings = match seconds {
        Some(_) => time_samplings(file.data(top[4], "the time samplings")?).ok_or_else(|| {
            file.fail(
                top[4] & !EMPTY_DATA,
                "the time samplings are cut short".into(),
            )
        })?,
        None => Vec::new(),
    };
    let at = seconds.map(|s| (s, &samplings[..]));
    let mut objects = Vec::with_capacity(found.len());
    for (name, geom, world) in found {
        let (curves, guide) = read_curves_object(&file, &name, geom, &indexed, world, at)?;
        let last = name.rsplit('/').next().unwrap_or(&name).to_string();
        objects.push((last, curves, guide));
    }
    Ok(objects)
}

/// A curves object: its path, its `.geom` compound, and the transform of
/// the `Xform` objects above it.
type Found = (String, Child, DMat4);

/// Walks the object tree; collects each curves object, with the product
/// of the transforms above it (`world`).
fn collect_curves(
    file: &Ogawa,
    object: Child,
    path: &str,
    indexed: &[String],
    world: DMat4,
    depth: usize,
    found: &mut Vec<Found>,
) -> Result<(), CurvesReadError> {
    let what = if path.is_empty() { "/" } else { path };
    if depth > MAX_DEPTH {
        return Err(file.fail(
            object,
            format!("{what}: objects nested deeper than {MAX_DEPTH}"),
        ));
    }
    let children = file.group(object, what)?;
    if children.len() < 2 {
        return Ok(());
    }
    let last = children[children.len() - 1];
    let block = file.data(last, &format!("{what}: object headers"))?;
    file.charge(last & !EMPTY_DATA, 2 * block.len() as u64, what)?;
    let headers = object_headers(block, indexed).ok_or_else(|| {
        file.fail(
            last & !EMPTY_DATA,
            format!("{what}: object headers end in the middle of a header"),
        )
    })?;
    if headers.len() + 2 > children.len() {
        return Err(file.fail(
            object,
            format!(
                "{what}: {} object headers for {} children",
                headers.len(),
                children.len() - 2
            ),
        ));
    }
    for (i, (name, metadata)) in headers.iter().enumerate() {
        file.check_name(last & !EMPTY_DATA, name, what)?;
        let length = path.len() + 1 + name.len();
        if length > MAX_PATH_BYTES {
            return Err(file.fail(
                object,
                format!(
                    "{}: a child's path of {length} bytes, longer than pelage's limit of {MAX_PATH_BYTES} (docs/limits.md)",
                    excerpt(what)
                ),
            ));
        }
        let child_path = format!("{path}/{name}");
        let group = children[i + 1];
        let schema = metadata_value(metadata, "schema");
        let mut child_world = world;
        if matches!(schema, Some("AbcGeom_Curve_v2" | "AbcGeom_Xform_v3")) {
            let properties = file.group(group, &child_path)?;
            let first = properties.first().copied().unwrap_or(0);
            let top = Compound::read(file, first, indexed, &child_path)?;
            if schema == Some("AbcGeom_Curve_v2") {
                let geom = top.get(".geom").ok_or_else(|| {
                    let message = format!("{child_path}: a curves object without .geom");
                    file.fail(group, message)
                })?;
                found.push((child_path.clone(), geom.1, world));
            } else if let Some(xform) = top.get(".xform") {
                let (local, inherits) = read_xform(file, xform.1, indexed, &child_path)?;
                child_world = if inherits { world * local } else { local };
            }
        }
        collect_curves(
            file,
            group,
            &child_path,
            indexed,
            child_world,
            depth + 1,
            found,
        )?;
    }
    Ok(())
}

/// An `Xform` object's transform (first sample) and whether it inherits
/// its parent's: the ops (a byte each: type × 16 + hint) read their
/// channels from `.vals` in order, and compose first op outermost, as
/// `XformSample::getMatrix` does (Imath's row vectors read as columns).
fn read_xform(
    file: &Ogawa,
    xform: Child,
    indexed: &[String],
    path: &str,
) -> Result<(DMat4, bool), CurvesReadError> {
    let what = format!("{path}/.xform");
    let compound = Compound::read(file, xform, indexed, &what)?;
    let inherits = match compound.get(".inherits") {
        Some(p) => first_sample(file, p, &what)?
            .first()
            .is_none_or(|&b| b != 0),
        None => true,
    };
    let Some(ops) = compound.get(".ops") else {
        return Ok((DMat4::IDENTITY, inherits));
    };
    let ops = first_sample(file, ops, &format!("{what}/.ops"))?;
    let vals: Vec<f64> = match compound.get(".vals") {
        Some(p) if p.0.pod == 11 => first_sample(file, p, &format!("{what}/.vals"))?
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
            .collect(),
        Some(_) => return Err(file.fail(xform, format!("{what}/.vals: not doubles"))),
        None => Vec::new(),
    };
    let mut channels = vals.iter().copied();
    let mut take = |n: usize| -> Option<Vec<f64>> {
        let v: Vec<f64> = channels.by_ref().take(n).collect();
        (v.len() == n).then_some(v)
    };
    let mut local = DMat4::IDENTITY;
    for (k, &op) in ops.iter().enumerate() {
        let short = || file.fail(xform, format!("{what}: op {k} has too few values in .vals"));
        let m = match op >> 4 {
            0 => DMat4::from_scale(DVec3::from_slice(&take(3).ok_or_else(short)?)),
            1 => DMat4::from_translation(DVec3::from_slice(&take(3).ok_or_else(short)?)),
            2 => {
                let v = take(4).ok_or_else(short)?;
                let axis = DVec3::new(v[0], v[1], v[2]).normalize_or_zero();
                DMat4::from_axis_angle(axis, v[3].to_radians())
            }
            3 => {
                let m: [f64; 16] = take(16).ok_or_else(short)?.try_into().expect("16 values");
                DMat4::from_cols_array(&m)
            }
            4 => DMat4::from_rotation_x(take(1).ok_or_else(short)?[0].to_radians()),
            5 => DMat4::from_rotation_y(take(1).ok_or_else(short)?[0].to_radians()),
            6 => DMat4::from_rotation_z(take(1).ok_or_else(short)?[0].to_radians()),
            t => {
                let message = format!("{what}: op {k} has the unknown type {t}");
                return Err(file.fail(xform, message));
            }
        };
        local *= m;
    }
    Ok((local, inherits))
}

/// A time sampling: time per cycle and the sample times of one cycle
/// (seconds). Acyclic samplings list every time.
#[derive(Debug, Clone)]
struct TimeSampling {
    /// The most samples a property of this sampling has.
    max_sample: u32,
    per_cycle: f64,
    times: Vec<f64>,
}

impl TimeSampling {
    fn acyclic(&self) -> bool {
        self.per_cycle >= f64::MAX / 64.0
    }

    /// The time of sample `k`.
    fn time(&self, k: usize) -> f64 {
        let n = self.times.len().max(1);
        if self.acyclic() {
            return self
                .times
                .get(k)
                .or(self.times.last())
                .copied()
                .unwrap_or(0.0);
        }
        self.times.get(k % n).copied().unwrap_or(0.0) + (k / n) as f64 * self.per_cycle
    }

    /// The sample (of `count`) whose time is nearest `seconds`.
    fn nearest(&self, seconds: f64, count: usize) -> usize {
        let n = self.times.len().max(1);
        // Candidates: every listed time (acyclic), or the cycles around
        // `seconds` (a file's sample count alone must not set the work).
        let candidates = if self.acyclic() {
            0..count.min(n)
        } else {
            let cycle = ((seconds - self.time(0)) / self.per_cycle).floor();
            let first = if cycle.is_finite() && cycle > 0.0 {
                (cycle as usize).saturating_sub(1).saturating_mul(n)
            } else {
                0
            };
            first.min(count.saturating_sub(1))..first.saturating_add(3 * n).min(count)
        };
        candidates
            .min_by(|&a, &b| {
                (self.time(a) - seconds)
                    .abs()
                    .total_cmp(&(self.time(b) - seconds).abs())
            })
            .unwrap_or(0)
    }
}

/// The archive's time samplings: per sampling, `u32` max sample, `f64`
/// time per cycle, `u32` samples a cycle and their `f64` times.
fn time_samplings(block: &[u8]) -> Option<Vec<TimeSampling>> {
    let mut out = Vec::new();
    let mut at = 0;
    let take = |at: &mut usize, n: usize| -> Option<&[u8]> {
        let bytes = block.get(*at..*at + n)?;
        *at += n;
        Some(bytes)
    };
    while at < block.len() {
        let max_sample = u32::from_le_bytes(take(&mut at, 4)?.try_into().ok()?);
        let per_cycle = f64::from_le_bytes(take(&mut at, 8)?.try_into().ok()?);
        let n = u32::from_le_bytes(take(&mut at, 4)?.try_into().ok()?) as usize;
        if n > (block.len() - at) / 8 {
            return None;
        }
        let times = (0..n)
            .map(|_| Some(f64::from_le_bytes(take(&mut at, 8)?.try_into().ok()?)))
            .collect::<Option<Vec<f64>>>()?;
        out.push(TimeSampling {
            max_sample,
            per_cycle,
            times,
        });
    }
    Some(out)
}

fn read_curves_object(
    file: &Ogawa,
    path: &str,
    geom: Child,
    indexed: &[String],
    world: DMat4,
    at: Option<(f64, &[TimeSampling])>,
) -> Result<(Curves, bool), CurvesReadError> {
    let what = |p: &str| format!("{path}/.geom/{p}");
    let mut guide = false;
    let at_child = geom;
    let fail = |message: String| file.fail(geom, message);
    let object_at = geom;
    let geom = Compound::read(file, geom, indexed, &what(""))?;
    let property = |name: &str, pod: &[u8], extent: u8| -> Result<Option<&[u8]>, CurvesReadError> {
        let Some(p) = geom.get(name) else {
            return Ok(None);
        };
        if p.0.kind == 0 {
            return Err(fail(format!(
                "{}: an indexed parameter; pelage reads plain arrays",
                what(name)
            )));
        }
        if !pod.contains(&p.0.pod) || p.0.extent != extent {
            return Err(fail(format!(
                "{}: type {} × {}, not what pelage reads",
                what(name),
                p.0.pod,
                p.0.extent
            )));
        }
        first_sample(file, p, &what(name)).map(Some)
    };
    // Into world space; normals turn with the inverse transpose.
    let moved = world != DMat4::IDENTITY;
    let turn = world.inverse().transpose();
    // Points at the asked time: the sample of P's own time sampling
    // nearest to it.
    let p_at = match (at, geom.get("P")) {
        (Some((seconds, samplings)), Some(p)) if p.0.samples > 1 => {
            let k = samplings
                .get(p.0.time_sampling as usize)
                .map_or(0, |ts| ts.nearest(seconds, p.0.samples as usize));
            property("P", &[10], 3)?;
            Some(sample(file, p, k, &what("P"))?)
        }
        _ => None,
    };
    let p_bytes = match p_at {
        Some(b) => Some(b),
        None => property("P", &[10], 3)?,
    };
    let points: Vec<Vec3> = match p_bytes {
        Some(b) => floats(b)
            .collect::<Vec<_>>()
            .chunks_exact(3)
            .map(Vec3::from_slice)
            .map(|p| match moved {
                true => world.transform_point3(p.as_dvec3()).as_vec3(),
                false => p,
            })
            .collect(),
        None => return Err(fail(format!("{}: no P", path))),
    };
    let counts: Vec<i32> = match property("nVertices", &[6], 1)? {
        Some(b) => b
            .chunks_exact(4)
            .map(|c| i32::from_le_bytes(c.try_into().expect("4 bytes")))
            .collect(),
        None => return Err(fail(format!("{}: no nVertices", path))),
    };
    if let Some(i) = counts.iter().position(|&c| c < 1) {
        return Err(fail(format!(
            "{}: curve {i} has {} points",
            what("nVertices"),
            counts[i]
        )));
    }
    let total: u64 = counts.iter().map(|&c| c as u64).sum();
    if total != points.len() as u64 {
        return Err(fail(format!(
            "{}: the curves' vertex counts add up to {total}, but P holds {} points",
            path,
            points.len()
        )));
    }
    let offsets: Vec<u32> = std::iter::once(0)
        .chain(counts.iter().scan(0u32, |end, &c| {
            *end += c as u32;
            Some(*end)
        }))
        .collect();
    let scope = |name: &str| {
        geom.get(name)
            .and_then(|p| metadata_value(&p.0.metadata, "geoScope").map(str::to_string))
    };
    let widths: Vec<f32> = match property("width", &[10], 1)? {
        None => vec![DEFAULT_WIDTH; points.len()],
        Some(b) => {
            let w: Vec<f32> = floats(b).collect();
            match (scope("width").as_deref(), w.len()) {
                (_, n) if n == points.len() => w,
                (Some("uni"), n) if n == counts.len() => counts
                    .iter()
                    .zip(&w)
                    .flat_map(|(&c, &v)| std::iter::repeat_n(v, c as usize))
                    .collect(),
                (_, 1) => vec![w[0]; points.len()],
                (s, n) => {
                    return Err(fail(format!(
                        "{}: {n} widths ({}) for {} curves of {} points",
                        what("width"),
                        s.unwrap_or("no scope"),
                        counts.len(),
                        points.len()
                    )));
                }
            }
        }
    };
    let mut curves = Curves::new(points, widths, offsets)
        .map_err(|error| file.curves_of(object_at, path, error))?;
    let n = curves.points().len();
    if let Some(b) = property("N", &[10], 3)?.filter(|b| b.len() == n * 12) {
        let normals = floats(b)
            .collect::<Vec<_>>()
            .chunks_exact(3)
            .map(Vec3::from_slice)
            .map(|n| match moved {
                true => turn
                    .transform_vector3(n.as_dvec3())
                    .as_vec3()
                    .normalize_or_zero(),
                false => n,
            })
            .collect();
        curves = curves
            .with_normals(normals)
            .map_err(|error| file.curves_of(object_at, path, error))?;
    }
    if let Some(arbitrary) = geom.get(".arbGeomParams").filter(|p| p.0.kind == 0) {
        let arb = Compound::read(file, arbitrary.1, indexed, &what(".arbGeomParams"))?;
        guide = arb.get("groom_guide").is_some();
        curves = with_arbitrary_params(file, at_child, &arb, path, curves)?;
    }
    Ok((curves, guide))
}

/// The curves with the `.arbGeomParams` pelage writes, where they have
/// the type and length it writes: colours, opacities, Unreal's groom
/// groups as regions, ids, root UVs and the hair-shading values (all six,
/// or none). Errors are the curves' refusals, at `geom`.
fn with_arbitrary_params(
    file: &Ogawa,
    geom: Child,
    arb: &Compound,
    path: &str,
    mut curves: Curves,
) -> Result<Curves, CurvesReadError> {
    let what = |p: &str| format!("{path}/.geom/{p}");
    let n = curves.points().len();
    let sample =
        |name: &str, pods: &[u8], extent: u8| -> Result<Option<(u8, &[u8])>, CurvesReadError> {
            match arb.get(name) {
                Some(p) if p.0.kind != 0 && pods.contains(&p.0.pod) && p.0.extent == extent => {
                    Ok(Some((p.0.pod, first_sample(file, p, &what(name))?)))
                }
                _ => Ok(None),
            }
        };
    if let Some((_, b)) = sample("groom_color", &[10], 3)?.filter(|(_, b)| b.len() == n * 12) {
        let colors = floats(b)
            .collect::<Vec<_>>()
            .chunks_exact(3)
            .map(Vec3::from_slice)
            .collect();
        curves = curves
            .with_colors(colors)
            .map_err(|error| file.curves_of(geom, path, error))?;
    }
    if let Some((_, b)) = sample("groom_opacity", &[10], 1)?.filter(|(_, b)| b.len() == n * 4) {
        curves = curves
            .with_opacities(floats(b).collect())
            .map_err(|error| file.curves_of(geom, path, error))?;
    }
    let curve_count = curves.curve_count();
    if let Some((_, b)) =
        sample("groom_group_id", &[6], 1)?.filter(|(_, b)| b.len() == curve_count * 4)
    {
        let regions: Option<Vec<u32>> = b
            .chunks_exact(4)
            .map(|c| u32::try_from(i32::from_le_bytes(c.try_into().expect("4"))).ok())
            .collect();
        if let Some(regions) = regions {
            curves = curves
                .with_regions(regions)
                .map_err(|error| file.curves_of(geom, path, error))?;
        }
    }
    if let Some((pod, b)) = sample("groom_id", &[6, 8], 1)? {
        let ids: Option<Vec<u64>> = if pod == 6 {
            b.chunks_exact(4)
                .map(|c| u64::try_from(i32::from_le_bytes(c.try_into().expect("4"))).ok())
                .collect()
        } else {
            b.chunks_exact(8)
                .map(|c| u64::try_from(i64::from_le_bytes(c.try_into().expect("8"))).ok())
                .collect()
        };
        if let Some(ids) = ids.filter(|ids| ids.len() == curve_count) {
            curves = curves
                .with_ids(ids)
                .map_err(|error| file.curves_of(geom, path, error))?;
        }
    }
    if let Some((_, b)) =
        sample("groom_root_uv", &[10], 2)?.filter(|(_, b)| b.len() == curve_count * 8)
    {
        let uvs = floats(b)
            .collect::<Vec<_>>()
            .chunks_exact(2)
            .map(Vec2::from_slice)
            .collect();
        curves = curves
            .with_root_uvs(uvs)
            .map_err(|error| file.curves_of(geom, path, error))?;
    }
    // Hair-shading values where all six are there, as pelage writes
    // them.
    let per_curve = |name: &str, extent: u8| -> Result<Option<Vec<f32>>, CurvesReadError> {
        Ok(sample(name, &[10], extent)?
            .filter(|(_, b)| b.len() == curve_count * 4 * extent as usize)
            .map(|(_, b)| floats(b).collect()))
    };
    let mut found: [Option<Vec<f32>>; 5] = Default::default();
    for (slot, name) in found.iter_mut().zip(HairShading::FLOAT_NAMES) {
        *slot = per_curve(name, 1)?;
    }
    let tint =
        per_curve(HairShading::TINT, 3)?.map(|t| t.chunks_exact(3).map(Vec3::from_slice).collect());
    if let Some(shading) = HairShading::from_found(found, tint) {
        curves = curves
            .with_shading(shading)
            .map_err(|error| file.curves_of(geom, path, error))?;
    }
    Ok(curves)
}
