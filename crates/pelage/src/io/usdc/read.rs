//! Reading a USD crate file (usdc) with every size checked: the
//! bootstrap, the table of contents, the six structural sections and the
//! values pelage reads (tokens, strings, numbers, vectors, matrices and
//! arrays of them, compressed or not), into openusd's in-memory layer so
//! the USD reader (`usd_read`) works on text and binary alike. The layout
//! is the writer's (`crate_file`), as OpenUSD's `crateFile.cpp` defines it,
//! versions 0.4 to 0.12.
//!
//! A size in the file is believed only once the bytes it claims are there:
//! a truncated, corrupted or hostile file is an error naming the byte and
//! the structure, never a panic or an allocation of a size the file only
//! claims. Sizes the bytes cannot bound (compressed integers decode to up
//! to 128 values a byte; many fields may point at one array) are charged
//! to one [`DecodeBudget`] for the whole read, and paths have a length
//! ceiling ([`MAX_PATH_BYTES`]); errors quote names and paths as short
//! excerpts. Fields of types pelage does not read (list ops, dictionaries,
//! …) are left out of the layer; of time samples only the earliest is
//! decoded (pelage reads the first frame of an animation).

use super::crate_file::MIN_COMPRESSED_ARRAY_SIZE;
use crate::error::Where;
use crate::io::read_error::{CurvesReadError, CurvesReadErrorKind as Kind, DecodeBudget, excerpt};
use crate::limits::MAX_PATH_BYTES;
use openusd::gf;
use openusd::sdf::{self, AbstractData, SpecType, Value};
use openusd::tf::Token;
use std::path::Path;

/// The checked bytes of a crate file.
struct Crate<'a> {
    bytes: &'a [u8],
    path: &'a Path,
    /// The format's minor version (the major is 0).
    minor: u8,
    /// Whether time-sampled values keep every sample or only the first.
    all_samples: bool,
    /// What the read may still decode.
    budget: DecodeBudget,
}

type Result<T> = std::result::Result<T, CurvesReadError>;

impl<'a> Crate<'a> {
    fn fail(&self, at: usize, message: String) -> CurvesReadError {
        CurvesReadError::new(
            self.path,
            Where::element("byte", at),
            Kind::Inconsistent(message),
        )
    }

    /// `n` bytes at `at`.
    fn take(&self, at: usize, n: usize, what: &str) -> Result<&'a [u8]> {
        at.checked_add(n)
            .and_then(|end| self.bytes.get(at..end))
            .ok_or_else(|| {
                self.fail(
                    at,
                    format!(
                        "{what}: {n} bytes past the end of the file ({} bytes)",
                        self.bytes.len()
                    ),
                )
            })
    }

    fn u64_at(&self, at: usize, what: &str) -> Result<u64> {
        Ok(u64::from_le_bytes(
            self.take(at, 8, what)?.try_into().expect("8 bytes"),
        ))
    }

    fn u32_at(&self, at: usize, what: &str) -> Result<u32> {
        Ok(u32::from_le_bytes(
            self.take(at, 4, what)?.try_into().expect("4 bytes"),
        ))
    }

    /// Takes `bytes` of decoded values from the read's budget.
    fn charge(&self, at: usize, bytes: u64, what: &str) -> Result<()> {
        self.budget
            .charge(bytes)
            .map_err(|e| self.fail(at, format!("{what}: {e}")))
    }

    /// A count of `size`-byte items at `at` that must fit in the file.
    fn count(&self, at: usize, value: u64, size: usize, what: &str) -> Result<usize> {
        let room = (self.bytes.len().saturating_sub(at) / size.max(1)) as u64;
        if value > room {
            return Err(self.fail(
                at,
                format!("{what}: {value} items of {size} bytes, but the file has room for {room}"),
            ));
        }
        Ok(value as usize)
    }

    /// `TfFastCompression`'s framing over LZ4 blocks, decompressed into at
    /// most `size` bytes (LZ4 turns a byte into at most 255, so no more
    /// than that is allocated whatever the file claims).
    fn decompress(&self, at: usize, compressed: &[u8], size: usize, what: &str) -> Result<Vec<u8>> {
        let size = size.min(compressed.len().saturating_mul(255) + 16);
        let bad = |e: String| self.fail(at, format!("{what}: {e}"));
        let (&chunks, mut rest) = compressed
            .split_first()
            .ok_or_else(|| bad("no compressed data".into()))?;
        let mut out = vec![0u8; size];
        if chunks == 0 {
            let n =
                lz4_flex::block::decompress_into(rest, &mut out).map_err(|e| bad(e.to_string()))?;
            out.truncate(n);
            return Ok(out);
        }
        let mut filled = 0;
        for _ in 0..chunks {
            let (len, body) = rest
                .split_first_chunk::<4>()
                .ok_or_else(|| bad("a chunk header past the end".into()))?;
            let len = i32::from_le_bytes(*len).max(0) as usize;
            let chunk = body
                .get(..len)
                .ok_or_else(|| bad("a chunk past the end".into()))?;
            filled += lz4_flex::block::decompress_into(chunk, &mut out[filled..])
                .map_err(|e| bad(e.to_string()))?;
            rest = &body[len..];
        }
        out.truncate(filled);
        Ok(out)
    }

    /// A compressed run of `count` integers at `at`: its compressed size,
    /// then the LZ4-framed integer coding. Returns the values and the
    /// offset after them.
    fn integers(
        &self,
        at: usize,
        count: usize,
        wide: bool,
        what: &str,
    ) -> Result<(Vec<i64>, usize)> {
        let size = self.u64_at(at, what)?;
        let size = self.count(at + 8, size, 1, what)?;
        let compressed = self.take(at + 8, size, what)?;
        let width = if wide { 8 } else { 4 };
        // Two bits a value is the densest the coding gets.
        if count > 0 && count / 4 > compressed.len().saturating_mul(255) {
            return Err(self.fail(
                at,
                format!("{what}: {count} integers cannot fit in {size} bytes"),
            ));
        }
        let coded_size = if count == 0 {
            0
        } else {
            width + count.div_ceil(4) + width * count
        };
        // The coding's buffer and the decoded values, before either is
        // allocated.
        let decoded = (coded_size as u64).saturating_add((count as u64).saturating_mul(8));
        self.charge(at, decoded, what)?;
        let coded = if count == 0 {
            Vec::new()
        } else {
            self.decompress(at + 8, compressed, coded_size, what)?
        };
        let values = decode_integers(&coded, count, wide)
            .ok_or_else(|| self.fail(at, format!("{what}: the integer coding ends early")))?;
        Ok((values, at + 8 + size))
    }
}

/// The inverse of `crate_file::encode_integers`; `None` if the bytes end
/// before `count` values.
fn decode_integers(bytes: &[u8], count: usize, wide: bool) -> Option<Vec<i64>> {
    if count == 0 {
        return Some(Vec::new());
    }
    let width = if wide { 8 } else { 4 };
    let read = |at: usize, n: usize| -> Option<i64> {
        let mut b = [0u8; 8];
        b[..n].copy_from_slice(bytes.get(at..at + n)?);
        Some((i64::from_le_bytes(b) << (64 - 8 * n)) >> (64 - 8 * n))
    };
    let common = read(0, width)?;
    let codes = width;
    let mut at = width + count.div_ceil(4);
    let mut previous = 0i64;
    let mut out = Vec::with_capacity(count);
    for i in 0..count {
        let code = (bytes.get(codes + i / 4)? >> (2 * (i % 4))) & 3;
        let n = [0, width / 4, width / 2, width][code as usize];
        let delta = if n == 0 { common } else { read(at, n)? };
        at += n;
        previous = if wide {
            previous.wrapping_add(delta)
        } else {
            (previous as i32).wrapping_add(delta as i32) as i64
        };
        out.push(previous);
    }
    Some(out)
}

/// The structure: tokens, strings, fields, field sets, paths, specs.
struct Structure {
    tokens: Vec<Token>,
    strings: Vec<u32>,
    fields: Vec<(u32, u64)>,
    fieldsets: Vec<u32>,
    paths: Vec<String>,
    specs: Vec<(u32, u32, u32)>,
}

/// Reads a usdc file into openusd's in-memory layer.
pub(crate) fn read_usdc(path: &Path, all_samples: bool) -> Result<Box<dyn AbstractData>> {
    let bytes = std::fs::read(path).map_err(|e| CurvesReadError::whole(path, Kind::Io(e)))?;
    read_usdc_bytes(&bytes, path, all_samples)
}

/// [`read_usdc`] of a file's bytes (`path` names it in errors).
pub(crate) fn read_usdc_bytes(
    bytes: &[u8],
    path: &Path,
    all_samples: bool,
) -> Result<Box<dyn AbstractData>> {
    let mut file = Crate {
        bytes,
        path,
        minor: 0,
        all_samples,
        budget: DecodeBudget::for_file(bytes.len()),
    };
    let head = file.take(0, 24, "the bootstrap header")?;
    if &head[..8] != b"PXR-USDC" {
        return Err(CurvesReadError::whole(
            path,
            Kind::Syntax("not a usdc file: it does not start with PXR-USDC".into()),
        ));
    }
    file.minor = head[9];
    if head[8] != 0 || !(4..=12).contains(&head[9]) {
        return Err(file.fail(
            8,
            format!(
                "crate format {}.{}.{}; pelage reads 0.4 to 0.12",
                head[8], head[9], head[10]
            ),
        ));
    }
    let toc = file.u64_at(16, "the table of contents' offset")? as usize;
    let sections = file.u64_at(toc, "the table of contents")?;
    let sections = file.count(toc + 8, sections, 32, "the table of contents")?;
    let mut at = std::collections::HashMap::new();
    for k in 0..sections {
        let entry = file.take(toc + 8 + 32 * k, 32, "a section entry")?;
        let name = String::from_utf8_lossy(&entry[..16])
            .trim_end_matches('\0')
            .to_string();
        let start = u64::from_le_bytes(entry[16..24].try_into().expect("8 bytes")) as usize;
        at.insert(name, start);
    }
    let section = |name: &str| {
        at.get(name)
            .copied()
            .ok_or_else(|| file.fail(toc, format!("the table of contents has no {name} section")))
    };
    let structure = read_structure(&file, &section)?;
    let mut data = sdf::Data::new();
    for &(path_index, fieldset, kind) in &structure.specs {
        let spec_path = structure.paths.get(path_index as usize).map(String::as_str);
        let spec_path = spec_path.ok_or_else(|| {
            file.fail(
                section("SPECS").unwrap_or(0),
                format!(
                    "a spec names path {path_index} of {}",
                    structure.paths.len()
                ),
            )
        })?;
        let kind = spec_type(kind).ok_or_else(|| {
            file.fail(
                section("SPECS").unwrap_or(0),
                format!("{}: spec type {kind}", excerpt(spec_path)),
            )
        })?;
        let sdf_path = sdf::Path::new(spec_path).map_err(|e| {
            file.fail(
                0,
                format!("{}: {}", excerpt(spec_path), excerpt(&e.to_string())),
            )
        })?;
        let quoted = excerpt(spec_path);
        data.create_spec(sdf_path.clone(), kind);
        let mut i = fieldset as usize;
        loop {
            let field = *structure.fieldsets.get(i).ok_or_else(|| {
                file.fail(
                    section("FIELDSETS").unwrap_or(0),
                    format!("{quoted}: its field set runs past the end"),
                )
            })?;
            if field == u32::MAX {
                break;
            }
            let &(token, rep) = structure.fields.get(field as usize).ok_or_else(|| {
                file.fail(
                    section("FIELDS").unwrap_or(0),
                    format!("{quoted}: field {field} of {}", structure.fields.len()),
                )
            })?;
            let name = structure.tokens.get(token as usize).ok_or_else(|| {
                file.fail(
                    section("FIELDS").unwrap_or(0),
                    format!("{quoted}: a field named by token {token}"),
                )
            })?;
            let what = format!("{quoted} {}", excerpt(name.as_str()));
            if let Some(value) = read_value(&file, &structure, rep, &what)? {
                data.set_field(&sdf_path, name.as_str(), value);
            }
            i += 1;
        }
    }
    Ok(Box::new(data))
}

fn spec_type(kind: u32) -> Option<SpecType> {
    Some(match kind {
        1 => SpecType::Attribute,
        2 => SpecType::Connection,
        3 => SpecType::Expression,
        4 => SpecType::Mapper,
        5 => SpecType::MapperArg,
        6 => SpecType::Prim,
        7 => SpecType::PseudoRoot,
        8 => SpecType::Relationship,
        9 => SpecType::RelationshipTarget,
        10 => SpecType::Variant,
        11 => SpecType::VariantSet,
        _ => return None,
    })
}

fn read_structure(file: &Crate, section: &dyn Fn(&str) -> Result<usize>) -> Result<Structure> {
    // TOKENS: count, uncompressed size, compressed size, LZ4.
    let at = section("TOKENS")?;
    let count = file.u64_at(at, "TOKENS")?;
    let size = file.u64_at(at + 8, "TOKENS")? as usize;
    let compressed = file.u64_at(at + 16, "TOKENS")?;
    let compressed = file.count(at + 24, compressed, 1, "TOKENS")?;
    // The text, and the tokens made of it.
    file.charge(at, (size as u64).saturating_mul(2), "TOKENS")?;
    let text = file.decompress(
        at + 24,
        file.take(at + 24, compressed, "TOKENS")?,
        size,
        "TOKENS",
    )?;
    if text.len() != size {
        return Err(file.fail(
            at,
            format!(
                "TOKENS: {} bytes of text where the section says {size}",
                text.len()
            ),
        ));
    }
    let tokens: Vec<Token> = text
        .split(|&b| b == 0)
        .take(text.iter().filter(|&&b| b == 0).count())
        .map(|t| Token::from(String::from_utf8_lossy(t).as_ref()))
        .collect();
    if tokens.len() as u64 != count {
        return Err(file.fail(
            at,
            format!(
                "TOKENS: {} tokens where the section says {count}",
                tokens.len()
            ),
        ));
    }
    // STRINGS: count, then token indices.
    let at = section("STRINGS")?;
    let n = file.u64_at(at, "STRINGS")?;
    let n = file.count(at + 8, n, 4, "STRINGS")?;
    file.charge(at, 4 * n as u64, "STRINGS")?;
    let strings = (0..n)
        .map(|i| file.u32_at(at + 8 + 4 * i, "STRINGS"))
        .collect::<Result<Vec<_>>>()?;
    // FIELDS: count, token indices (integers), reps (LZ4).
    let at = section("FIELDS")?;
    let n = file.u64_at(at, "FIELDS")?;
    let n = file.count(at + 8, n, 1, "FIELDS")?;
    let (names, next) = file.integers(at + 8, n, false, "FIELDS: names")?;
    let size = file.u64_at(next, "FIELDS: values")?;
    let size = file.count(next + 8, size, 1, "FIELDS: values")?;
    file.charge(next, 8 * n as u64, "FIELDS: values")?;
    let reps = file.decompress(
        next + 8,
        file.take(next + 8, size, "FIELDS: values")?,
        8 * n,
        "FIELDS: values",
    )?;
    if reps.len() != 8 * n {
        return Err(file.fail(
            next,
            format!("FIELDS: {} values for {n} fields", reps.len() / 8),
        ));
    }
    let fields = names
        .iter()
        .zip(reps.chunks_exact(8))
        .map(|(&t, r)| (t as u32, u64::from_le_bytes(r.try_into().expect("8 bytes"))))
        .collect();
    // FIELDSETS: count, integers.
    let at = section("FIELDSETS")?;
    let n = file.u64_at(at, "FIELDSETS")?;
    let n = file.count(at + 8, n, 1, "FIELDSETS")?;
    let (sets, _) = file.integers(at + 8, n, false, "FIELDSETS")?;
    let fieldsets = sets.iter().map(|&s| s as u32).collect();
    // PATHS: the path count, the entry count, then path indices, element
    // tokens (negative: a property) and jumps.
    let at = section("PATHS")?;
    let n_paths = file.u64_at(at, "PATHS")?;
    let n_paths = file.count(at + 8, n_paths, 1, "PATHS")?;
    let n = file.u64_at(at + 8, "PATHS")?;
    let n = file.count(at + 16, n, 1, "PATHS")?;
    let (indices, next) = file.integers(at + 16, n, false, "PATHS: indices")?;
    let (elements, next) = file.integers(next, n, false, "PATHS: elements")?;
    let (jumps, _) = file.integers(next, n, false, "PATHS: jumps")?;
    let paths = build_paths(file, at, n_paths, &indices, &elements, &jumps, &tokens)?;
    // SPECS: count, path indices, field set starts, types.
    let at = section("SPECS")?;
    let n = file.u64_at(at, "SPECS")?;
    let n = file.count(at + 8, n, 1, "SPECS")?;
    let (spec_paths, next) = file.integers(at + 8, n, false, "SPECS: paths")?;
    let (spec_sets, next) = file.integers(next, n, false, "SPECS: field sets")?;
    let (spec_types, _) = file.integers(next, n, false, "SPECS: types")?;
    let specs = (0..n)
        .map(|i| {
            (
                spec_paths[i] as u32,
                spec_sets[i] as u32,
                spec_types[i] as u32,
            )
        })
        .collect();
    Ok(Structure {
        tokens,
        strings,
        fields,
        fieldsets,
        paths,
        specs,
    })
}

/// Rebuilds the path strings from the depth-first entries (see
/// `crate_file::Structure::paths_section` for the jumps).
#[allow(clippy::too_many_arguments)]
fn build_paths(
    file: &Crate,
    at: usize,
    n_paths: usize,
    indices: &[i64],
    elements: &[i64],
    jumps: &[i64],
    tokens: &[Token],
) -> Result<Vec<String>> {
    let mut paths = vec![String::new(); n_paths];
    let bad = |i: usize, what: &str| file.fail(at, format!("PATHS: entry {i}: {what}"));
    // (entry, parent path) still to visit.
    let mut pending: Vec<(usize, Option<String>)> = if indices.is_empty() {
        vec![]
    } else {
        vec![(0, None)]
    };
    let mut visited = 0usize;
    while let Some((mut i, mut parent)) = pending.pop() {
        loop {
            visited += 1;
            if visited > indices.len() || i >= indices.len() {
                return Err(bad(i, "the jumps lead outside the entries or in a loop"));
            }
            let this = match &parent {
                None => "/".to_string(),
                Some(p) => {
                    let element = elements[i];
                    let token = tokens
                        .get(element.unsigned_abs() as usize)
                        .ok_or_else(|| bad(i, "an element token past the tokens"))?;
                    let length = p.len() + 1 + token.as_str().len();
                    if length > MAX_PATH_BYTES {
                        return Err(bad(
                            i,
                            &format!(
                                "a path of {length} bytes under {}, longer than pelage's limit of {MAX_PATH_BYTES} (docs/limits.md)",
                                excerpt(p)
                            ),
                        ));
                    }
                    // The path and the copy its slot keeps.
                    file.charge(at, 2 * length as u64, "PATHS")?;
                    if element < 0 {
                        format!("{p}.{}", token.as_str())
                    } else if p == "/" {
                        format!("/{}", token.as_str())
                    } else {
                        format!("{p}/{}", token.as_str())
                    }
                }
            };
            let slot = usize::try_from(indices[i]).ok().filter(|&s| s < n_paths);
            *paths
                .get_mut(slot.ok_or_else(|| bad(i, "a path index past the paths"))?)
                .expect("checked") = this.clone();
            let jump = jumps[i];
            let has_child = jump > 0 || jump == -1;
            let has_sibling = jump >= 0;
            if has_child && has_sibling {
                let sibling = usize::try_from(i as i64 + jump)
                    .map_err(|_| bad(i, "a jump before the start"))?;
                file.charge(at, parent.as_ref().map_or(0, |p| p.len() as u64), "PATHS")?;
                pending.push((sibling, parent.clone()));
            }
            if has_child {
                parent = Some(this);
                i += 1;
            } else if has_sibling {
                i += 1;
            } else {
                break;
            }
        }
    }
    Ok(paths)
}

/// The value a field's rep stands for, where pelage reads its type.
fn read_value(file: &Crate, s: &Structure, rep: u64, what: &str) -> Result<Option<Value>> {
    let ty = ((rep >> 48) & 0xff) as u8;
    let array = rep & (1 << 63) != 0;
    let inlined = rep & (1 << 62) != 0;
    let compressed = rep & (1 << 61) != 0;
    let payload = rep & ((1 << 48) - 1);
    let token = |i: u64| {
        s.tokens
            .get(i as usize)
            .cloned()
            .ok_or_else(|| file.fail(0, format!("{what}: token {i} of {}", s.tokens.len())))
    };
    if inlined {
        let p = payload as u32;
        // Vectors and matrices whose components are small integers are
        // inlined as signed bytes (OpenUSD's `_IsInlinable`).
        let byte = |k: usize| f64::from(p.to_le_bytes()[k] as i8);
        return Ok(Some(match ty {
            1 => Value::Bool(p != 0),
            3 => Value::Int(p as i32),
            8 => Value::Float(f32::from_bits(p)),
            9 => Value::Double(f64::from(f32::from_bits(p))),
            10 => Value::String(
                s.strings
                    .get(p as usize)
                    .and_then(|&t| s.tokens.get(t as usize))
                    .map(|t| t.as_str().to_string())
                    .ok_or_else(|| {
                        file.fail(0, format!("{what}: string {p} of {}", s.strings.len()))
                    })?,
            ),
            11 => Value::Token(token(payload)?),
            15 => {
                let mut m = [0f64; 16];
                for k in 0..4 {
                    m[5 * k] = byte(k);
                }
                Value::Matrix4d(gf::Matrix4d(m))
            }
            20 => Value::Vec2f(gf::Vec2f {
                x: byte(0) as f32,
                y: byte(1) as f32,
            }),
            23 => Value::Vec3d(gf::Vec3d {
                x: byte(0),
                y: byte(1),
                z: byte(2),
            }),
            24 => Value::Vec3f(gf::Vec3f {
                x: byte(0) as f32,
                y: byte(1) as f32,
                z: byte(2) as f32,
            }),
            42 => Value::Specifier(match p {
                1 => sdf::Specifier::Over,
                2 => sdf::Specifier::Class,
                _ => sdf::Specifier::Def,
            }),
            44 => Value::Variability(if p == 1 {
                sdf::Variability::Uniform
            } else {
                sdf::Variability::Varying
            }),
            _ => return Ok(None),
        }));
    }
    let at = payload as usize;
    if array {
        if payload == 0 {
            return Ok(match ty {
                3 => Some(Value::IntVec(Vec::new())),
                5 => Some(Value::Int64Vec(Vec::new())),
                8 => Some(Value::FloatVec(Vec::new())),
                9 => Some(Value::DoubleVec(Vec::new())),
                20 => Some(Value::Vec2fVec(Vec::new())),
                23 => Some(Value::Vec3dVec(Vec::new())),
                24 => Some(Value::Vec3fVec(Vec::new())),
                11 => Some(Value::TokenVec(Vec::new())),
                _ => None,
            });
        }
        return read_array(file, &s.tokens, at, ty, compressed, what);
    }
    Ok(Some(match ty {
        46 => return time_samples(file, s, at, what),
        48 => {
            let n = file.u64_at(at, what)?;
            let n = file.count(at + 8, n, 8, what)?;
            file.charge(at, 8 * n as u64, what)?;
            Value::DoubleVec(doubles(file.take(at + 8, 8 * n, what)?))
        }
        9 => Value::Double(f64::from_le_bytes(
            file.take(at, 8, what)?.try_into().expect("8"),
        )),
        23 => {
            let v: Vec<f64> = doubles(file.take(at, 24, what)?);
            Value::Vec3d(gf::Vec3d {
                x: v[0],
                y: v[1],
                z: v[2],
            })
        }
        24 => {
            let v = floats(file.take(at, 12, what)?);
            Value::Vec3f(gf::Vec3f {
                x: v[0],
                y: v[1],
                z: v[2],
            })
        }
        15 => Value::Matrix4d(gf::Matrix4d(
            doubles(file.take(at, 128, what)?).try_into().expect("16"),
        )),
        41 => {
            let n = file.u64_at(at, what)?;
            let n = file.count(at + 8, n, 4, what)?;
            file.charge(at, 16 * n as u64, what)?;
            let tokens = (0..n)
                .map(|k| {
                    file.u32_at(at + 8 + 4 * k, what)
                        .and_then(|t| token(t as u64))
                })
                .collect::<Result<Vec<_>>>()?;
            Value::TokenVec(tokens)
        }
        _ => return Ok(None),
    }))
}

/// A field's time samples: all of them when the file is read with
/// `all_samples`, otherwise the earliest as a one-sample list (what the
/// curve readers use, decoding one array instead of a frame each). At
/// `at`: an offset to the times' rep, the rep, an offset to the values,
/// their count and their reps; offsets count from where they are written.
fn time_samples(file: &Crate, s: &Structure, at: usize, what: &str) -> Result<Option<Value>> {
    let jump = |from: usize| -> Result<usize> {
        let offset = file.u64_at(from, what)? as i64;
        usize::try_from(from as i64 + offset).map_err(|_| {
            file.fail(
                from,
                format!("{what}: a time-samples offset before the file"),
            )
        })
    };
    let times_at = jump(at)?;
    let times_rep = file.u64_at(times_at, what)?;
    // Times are a list of doubles, not themselves time samples.
    if (times_rep >> 48) & 0xff == 46 {
        return Err(file.fail(
            times_at,
            format!("{what}: time samples nested in their times"),
        ));
    }
    let times = match read_value(file, s, times_rep, what)? {
        Some(Value::DoubleVec(t)) => t,
        _ => {
            return Err(file.fail(
                times_at,
                format!("{what}: the sample times are not doubles"),
            ));
        }
    };
    let values_at = jump(times_at + 8)?;
    let n = file.u64_at(values_at, what)?;
    let n = file.count(values_at + 8, n, 8, what)?;
    if n != times.len() {
        return Err(file.fail(
            values_at,
            format!("{what}: {n} values for {} times", times.len()),
        ));
    }
    let sample = |k: usize| -> Result<Option<(f64, Value)>> {
        let rep = file.u64_at(values_at + 8 + 8 * k, what)?;
        if (rep >> 48) & 0xff == 46 {
            return Err(file.fail(
                values_at,
                format!("{what}: time samples nested in a sample"),
            ));
        }
        Ok(read_value(file, s, rep, what)?.map(|v| (times[k], v)))
    };
    if file.all_samples {
        let mut samples = Vec::with_capacity(n);
        for k in 0..n {
            samples.extend(sample(k)?);
        }
        return Ok(Some(Value::TimeSamples(samples)));
    }
    let Some(first) = (0..n).min_by(|&a, &b| times[a].total_cmp(&times[b])) else {
        return Ok(Some(Value::TimeSamples(Vec::new())));
    };
    Ok(sample(first)?.map(|v| Value::TimeSamples(vec![v])))
}

fn floats(b: &[u8]) -> Vec<f32> {
    b.chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().expect("4")))
        .collect()
}

fn doubles(b: &[u8]) -> Vec<f64> {
    b.chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().expect("8")))
        .collect()
}

/// An array at `at`: its element count (a `u32` before 0.7, after a shape
/// count before 0.5), then its values, raw or compressed.
fn read_array(
    file: &Crate,
    tokens: &[Token],
    mut at: usize,
    ty: u8,
    compressed: bool,
    what: &str,
) -> Result<Option<Value>> {
    let (minor, element) = (file.minor, element_size(ty));
    let Some(element) = element else {
        return Ok(None);
    };
    if minor < 5 {
        at += 4;
    }
    let count = if minor < 7 {
        let n = file.u32_at(at, what)? as u64;
        at += 4;
        n
    } else {
        let n = file.u64_at(at, what)?;
        at += 8;
        n
    };
    let integer = matches!(ty, 3 | 5);
    let floating = matches!(ty, 8 | 9);
    // The values as pelage holds them (compressed ones are charged again
    // for their decoding below).
    file.charge(at, count.saturating_mul(element as u64), what)?;
    let compressed = compressed && count as usize >= MIN_COMPRESSED_ARRAY_SIZE;
    if compressed && integer && minor >= 5 {
        let count = usize::try_from(count).unwrap_or(usize::MAX);
        let (v, _) = file.integers(at, count, ty == 5, what)?;
        return Ok(Some(match ty {
            3 => Value::IntVec(v.into_iter().map(|x| x as i32).collect()),
            _ => Value::Int64Vec(v),
        }));
    }
    if compressed && floating && minor >= 6 {
        let count = usize::try_from(count).unwrap_or(usize::MAX);
        let code = file.take(at, 1, what)?[0];
        let values: Vec<f64> = match code {
            b'i' => {
                file.charge(at, 8 * count as u64, what)?;
                file.integers(at + 1, count, false, what)?
                    .0
                    .into_iter()
                    .map(|x| x as f64)
                    .collect()
            }
            b't' => {
                let n = file.u32_at(at + 1, what)? as u64;
                let n = file.count(at + 5, n, element, what)?;
                file.charge(at, 8 * n as u64 + 8 * count as u64, what)?;
                let table = file.take(at + 5, n * element, what)?;
                let table: Vec<f64> = if ty == 8 {
                    floats(table).into_iter().map(f64::from).collect()
                } else {
                    doubles(table)
                };
                let (indices, _) = file.integers(at + 5 + n * element, count, false, what)?;
                indices
                    .iter()
                    .map(|&i| table.get(i as usize).copied())
                    .collect::<Option<Vec<f64>>>()
                    .ok_or_else(|| {
                        file.fail(at, format!("{what}: an index past the lookup table"))
                    })?
            }
            c => {
                return Err(file.fail(
                    at,
                    format!("{what}: compressed floats with the unknown code {c}"),
                ));
            }
        };
        return Ok(Some(if ty == 8 {
            Value::FloatVec(values.into_iter().map(|x| x as f32).collect())
        } else {
            Value::DoubleVec(values)
        }));
    }
    let count = file.count(at, count, element, what)?;
    let bytes = file.take(at, count * element, what)?;
    if ty == 11 {
        let tokens = bytes
            .chunks_exact(4)
            .map(|c| {
                let i = u32::from_le_bytes(c.try_into().expect("4")) as usize;
                file_token(file, tokens, i, what)
            })
            .collect::<Result<Vec<_>>>()?;
        return Ok(Some(Value::TokenVec(tokens)));
    }
    Ok(Some(match ty {
        3 => Value::IntVec(
            bytes
                .chunks_exact(4)
                .map(|c| i32::from_le_bytes(c.try_into().expect("4")))
                .collect(),
        ),
        5 => Value::Int64Vec(
            bytes
                .chunks_exact(8)
                .map(|c| i64::from_le_bytes(c.try_into().expect("8")))
                .collect(),
        ),
        8 => Value::FloatVec(floats(bytes)),
        9 => Value::DoubleVec(doubles(bytes)),
        20 => Value::Vec2fVec(bytemuck::pod_collect_to_vec(bytes)),
        23 => Value::Vec3dVec(bytemuck::pod_collect_to_vec(bytes)),
        24 => Value::Vec3fVec(bytemuck::pod_collect_to_vec(bytes)),
        _ => return Ok(None),
    }))
}

fn file_token(file: &Crate, tokens: &[Token], i: usize, what: &str) -> Result<Token> {
    tokens
        .get(i)
        .cloned()
        .ok_or_else(|| file.fail(0, format!("{what}: token {i} of {}", tokens.len())))
}

/// Bytes of one element of the array types pelage reads.
fn element_size(ty: u8) -> Option<usize> {
    Some(match ty {
        3 | 8 | 11 => 4,
        5 | 9 | 20 => 8,
        23 => 24,
        24 => 12,
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    //! Hand-made crate files of the shapes a hostile file takes: each is
    //! small, and claims (or, decoded, would build) gigabytes. The ignored
    //! test at the end writes them into the hostile suite's files.
    use super::super::crate_file::{
        BOOTSTRAP_SIZE, Counted, ROOT_PATH, Spec, SpecType, Structure, VERSION, ValueRep,
        ValueType, encode_integers,
    };
    use super::*;
    use std::io::Write;

    /// A layer with one prim, `/root`, whose attributes `a0`, `a1`, … have
    /// the `default` values `reps`, which point into `body` (written at
    /// [`BOOTSTRAP_SIZE`]); `chain` more prims nested each in the last,
    /// all named `name`.
    fn crafted(body: &[u8], reps: &[ValueRep], chain: usize, name: &str) -> Vec<u8> {
        let mut out = Counted {
            inner: Vec::new(),
            position: 0,
        };
        out.write_all(&[0u8; BOOTSTRAP_SIZE]).unwrap();
        out.write_all(body).unwrap();
        let mut s = Structure::new("root");
        let prim = s.child_path(ROOT_PATH, "root", false);
        for (k, &rep) in reps.iter().enumerate() {
            let path = s.child_path(prim, &format!("a{k}"), true);
            let fields = vec![
                (
                    s.token("typeName"),
                    ValueRep::inlined(ValueType::Token, s.token("int[]")),
                ),
                (s.token("default"), rep),
            ];
            s.specs.push(Spec {
                path,
                kind: SpecType::Attribute,
                fields,
            });
        }
        let mut parent = prim;
        for _ in 0..chain {
            parent = s.child_path(parent, name, false);
        }
        let specifier = s.token("specifier");
        s.specs.push(Spec {
            path: prim,
            kind: SpecType::Prim,
            fields: vec![(specifier, ValueRep::inlined(ValueType::Specifier, 0))],
        });
        s.specs.push(Spec {
            path: ROOT_PATH,
            kind: SpecType::PseudoRoot,
            fields: Vec::new(),
        });
        // The path tree is walked recursively: a deep chain needs a deep
        // stack.
        let toc = std::thread::scope(|scope| {
            std::thread::Builder::new()
                .stack_size(1 << 30)
                .spawn_scoped(scope, || s.write_sections(&mut out).unwrap())
                .unwrap()
                .join()
                .unwrap()
        });
        let mut bytes = out.inner;
        bytes[..8].copy_from_slice(b"PXR-USDC");
        bytes[8..11].copy_from_slice(&VERSION);
        bytes[16..24].copy_from_slice(&toc.to_le_bytes());
        bytes
    }

    /// A compressed `int[]` of `count` values 1, 2, 3, … whose coding is
    /// real LZ4 (it decodes, to `count` values), or with `decodes` false,
    /// the smallest body the compression ratio check lets through (a
    /// literal run of zeros, not the coding).
    fn integer_array(count: u64, decodes: bool) -> Vec<u8> {
        let coded = if decodes {
            encode_integers(std::iter::repeat_n(1i64, 1), false)
                .into_iter()
                .take(4)
                .chain(std::iter::repeat_n(0u8, count.div_ceil(4) as usize))
                .collect::<Vec<u8>>()
        } else {
            Vec::new()
        };
        let mut framed = vec![0u8];
        if decodes {
            framed.extend(lz4_flex::block::compress(&coded));
        } else {
            // One literal run: token, length bytes, the literals.
            let literals = (count / 4).div_ceil(255) as usize + 1;
            framed.push(0xf0);
            let mut rest = literals - 15;
            while rest >= 255 {
                framed.push(255);
                rest -= 255;
            }
            framed.push(rest as u8);
            framed.extend(std::iter::repeat_n(0u8, literals));
        }
        let mut body = count.to_le_bytes().to_vec();
        body.extend((framed.len() as u64).to_le_bytes());
        body.extend(framed);
        body
    }

    /// 60,000 prims nested each in the last, named `name`, the file padded
    /// at its end so the path count fits the bytes after it.
    fn deep_chain(name: &str) -> Vec<u8> {
        let mut file = crafted(&[], &[], 60_000, name);
        file.extend(std::iter::repeat_n(0u8, 70_000));
        file
    }

    fn int_array_at(offset: usize) -> ValueRep {
        ValueRep::array(ValueType::Int, offset as u64, true)
    }

    fn read(bytes: &[u8]) -> std::result::Result<Box<dyn AbstractData>, String> {
        read_usdc_bytes(bytes, Path::new("bad.usdc"), false).map_err(|e| e.to_string())
    }

    fn read_err(bytes: &[u8]) -> String {
        match read(bytes) {
            Ok(_) => panic!("read a hostile file"),
            Err(e) => e,
        }
    }

    /// An array claiming 300 million integers in 300 KB: the compression
    /// ratio allows it, the budget does not, and nothing is allocated.
    #[test]
    fn integers_claimed_past_the_budget_are_refused_before_decoding() {
        let file = crafted(
            &integer_array(300_000_000, false),
            &[int_array_at(BOOTSTRAP_SIZE)],
            0,
            "",
        );
        let err = read_err(&file);
        assert!(err.starts_with("bad.usdc: byte "), "{err}");
        assert!(err.contains("/root.a0 default:"), "{err}");
        assert!(err.contains("docs/limits.md"), "{err}");
    }

    /// Many fields may share one array, and each decode is its own
    /// allocation: a 20-million-integer array decodes for three fields
    /// and is refused at the fourth.
    #[test]
    fn a_shared_array_is_charged_at_each_decode() {
        let body = integer_array(20_000_000, true);
        let one = crafted(&body, &[int_array_at(BOOTSTRAP_SIZE)], 0, "");
        let Ok(layer) = read(&one) else {
            panic!("one array of 20 million integers is within the budget")
        };
        let path = sdf::Path::new("/root.a0").unwrap();
        match layer.get_field(&path, "default").as_deref() {
            Ok(Value::IntVec(v)) => {
                assert_eq!(v.len(), 20_000_000);
                assert_eq!((v[0], v[19_999_999]), (1, 20_000_000));
            }
            _ => panic!("/root.a0 is not the int array"),
        }
        let eight = crafted(&body, &[int_array_at(BOOTSTRAP_SIZE); 8], 0, "");
        let err = read_err(&eight);
        assert!(err.contains("/root.a3 default:"), "{err}");
        assert!(err.contains("docs/limits.md"), "{err}");
    }

    /// A chain of prims nested 60,000 deep under a 2 KB name: the path
    /// ceiling stops it at 32 levels, and the error quotes the path as an
    /// excerpt.
    #[test]
    fn a_deep_chain_of_long_names_stops_at_the_path_ceiling() {
        let name = "n".repeat(2048);
        let file = deep_chain(&name);
        let err = read_err(&file);
        assert!(err.contains("longer than pelage's limit of 65536"), "{err}");
        assert!(err.len() < 600, "{} bytes: {err}", err.len());
    }

    /// Writes the crafted files the hostile suite runs the binary on.
    #[test]
    #[ignore = "writes tests/hostile/files; run by hand after changing a crafted file"]
    fn write_hostile_suite_files() {
        let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/hostile/files");
        let write = |name: &str, bytes: Vec<u8>| std::fs::write(folder.join(name), bytes).unwrap();
        // 1.1 billion integers in 1.1 MB of real LZ4: 8.8 GB decoded.
        let at = BOOTSTRAP_SIZE;
        write(
            "usdc_integer_bomb.usdc",
            crafted(
                &integer_array(1_100_000_000, true),
                &[int_array_at(at)],
                0,
                "",
            ),
        );
        // Eight fields at one array of 400 million integers: 1.6 GB each.
        write(
            "usdc_shared_array.usdc",
            crafted(
                &integer_array(400_000_000, true),
                &[int_array_at(at); 8],
                0,
                "",
            ),
        );
        write("usdc_deep_long_paths.usdc", deep_chain(&"n".repeat(2048)));
        // The fuzz harness's seeds: the same shapes, small enough to
        // mutate fast (a chain of 40 levels passes the path ceiling; eight
        // fields share an array).
        let seeds = folder.join("../fuzz/usdc");
        let seed = |name: &str, bytes: Vec<u8>| std::fs::write(seeds.join(name), bytes).unwrap();
        seed(
            "deep_long_paths.usdc",
            crafted(&[], &[], 40, &"n".repeat(2048)),
        );
        seed(
            "shared_array.usdc",
            crafted(&integer_array(100_000, true), &[int_array_at(at); 8], 0, ""),
        );
    }
}
