//! The USD crate file (usdc) at the level of bytes: value representations,
//! the integer coding and LZ4 framing of compressed arrays, and the
//! structural sections (tokens, strings, fields, field sets, paths, specs)
//! with their table of contents. The layout is OpenUSD's
//! `pxr/usd/sdf/crateFile.cpp` (with `integerCoding.cpp` and
//! `tf/fastCompression.cpp`), version 0.8.0: what usd-core 26 writes by
//! default and every USD since 2020 (Blender 5's included) reads.
//!
//! A file is: an 88-byte bootstrap (`PXR-USDC`, the version, the offset of
//! the table of contents), the values that do not fit in a field's 8 bytes
//! (arrays, doubles, token lists, time samples) anywhere after it, then the
//! six structural sections and the table of contents. Values come first so
//! a writer can stream them and keep only the small structure in memory.

use rayon::prelude::*;
use std::collections::HashMap;
use std::io::{self, Write};

/// The crate format version written.
pub(super) const VERSION: [u8; 3] = [0, 8, 0];
/// Bytes of the bootstrap header: ident, version, TOC offset, 8 reserved
/// words.
pub(super) const BOOTSTRAP_SIZE: usize = 88;
/// Integer arrays at least this long are written compressed. OpenUSD's
/// reader decides by the same threshold, so shorter ones must not be.
pub(super) const MIN_COMPRESSED_ARRAY_SIZE: usize = 16;
/// The most LZ4 compresses in one block (`LZ4_MAX_INPUT_SIZE`); longer
/// input is split into chunks, as `TfFastCompression` does.
const LZ4_MAX_INPUT_SIZE: usize = 0x7E00_0000;

/// The value types pelage writes (`Usd_CrateDataTypeEnum`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub(super) enum ValueType {
    Bool = 1,
    Int = 3,
    Int64 = 5,
    Float = 8,
    Double = 9,
    String = 10,
    Token = 11,
    Vec2f = 20,
    Vec3f = 24,
    TokenListOp = 32,
    PathListOp = 34,
    TokenVector = 41,
    Specifier = 42,
    Variability = 44,
    TimeSamples = 46,
    DoubleVector = 48,
}

/// A field's value as stored in the fields table: the type in bits 48–55,
/// flags for array, inlined and compressed in bits 63, 62 and 61, and 48
/// bits of payload — the value itself when inlined, else the file offset
/// where it is written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(super) struct ValueRep(pub u64);

impl ValueRep {
    const ARRAY: u64 = 1 << 63;
    const INLINED: u64 = 1 << 62;
    const COMPRESSED: u64 = 1 << 61;
    const PAYLOAD: u64 = (1 << 48) - 1;

    /// A value held in the rep itself (a token or string index, a bool,
    /// an enum).
    pub fn inlined(ty: ValueType, payload: u32) -> Self {
        Self(Self::INLINED | (ty as u64) << 48 | payload as u64)
    }

    /// A value written at `offset`.
    pub fn at(ty: ValueType, offset: u64) -> Self {
        debug_assert!(offset <= Self::PAYLOAD);
        Self((ty as u64) << 48 | (offset & Self::PAYLOAD))
    }

    /// An array written at `offset` (0 for an empty array, which has no
    /// bytes in the file).
    pub fn array(ty: ValueType, offset: u64, compressed: bool) -> Self {
        let flags = Self::ARRAY | if compressed { Self::COMPRESSED } else { 0 };
        Self(flags | Self::at(ty, offset).0)
    }
}

/// Kinds of spec (`SdfSpecType`) pelage writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub(super) enum SpecType {
    Attribute = 1,
    Prim = 6,
    PseudoRoot = 7,
    Relationship = 8,
}

/// The header byte of a list op (`_ListOpHeader`): which of its lists
/// follow, each as a count and the items, in the order explicit, added,
/// prepended, appended, deleted, ordered.
pub(super) mod list_op {
    /// The list replaces what weaker layers say (`rel x = </a>`).
    pub const EXPLICIT: u8 = 1 << 0;
    pub const HAS_EXPLICIT_ITEMS: u8 = 1 << 1;
    pub const HAS_PREPENDED_ITEMS: u8 = 1 << 5;
}

/// `Usd_IntegerCompression`'s coding of a run of integers before LZ4: a
/// common difference between neighbours, then a 2-bit code per value
/// (common, or a difference of ¼, ½ or the full width), then the
/// differences that are not the common one at their code's width.
/// `wide` selects 64-bit integers (widths 2/4/8 bytes) over 32-bit ones
/// (1/2/4); values are given as `i64` either way, wrapped to the width.
pub(super) fn encode_integers(
    values: impl ExactSizeIterator<Item = i64> + Clone,
    wide: bool,
) -> Vec<u8> {
    let count = values.len();
    let wrap = |d: i64| if wide { d } else { d as i32 as i64 };
    let deltas = values.scan(0i64, |previous, v| {
        let delta = wrap(v.wrapping_sub(*previous));
        *previous = v;
        Some(delta)
    });
    // The common difference: any choice decodes right; the majority (by
    // Boyer–Moore's vote, one pass, no table) codes best where there is
    // one, as in curve counts (all equal) and ids (steps of 1).
    let (mut common, mut votes) = (0i64, 0usize);
    for d in deltas.clone() {
        if votes == 0 {
            common = d;
        }
        votes = if d == common { votes + 1 } else { votes - 1 };
    }
    let width = if wide { 8 } else { 4 };
    let mut out = Vec::with_capacity(width + count.div_ceil(4) + count * width / 2);
    if wide {
        out.extend_from_slice(&common.to_le_bytes());
    } else {
        out.extend_from_slice(&(common as i32).to_le_bytes());
    }
    let codes_at = out.len();
    out.resize(codes_at + count.div_ceil(4), 0);
    for (i, d) in deltas.enumerate() {
        let (code, bytes) = if d == common {
            (0u8, 0)
        } else if d == d as i8 as i64 && !wide || d == d as i16 as i64 && wide {
            (1, width / 4)
        } else if d == d as i16 as i64 && !wide || d == d as i32 as i64 && wide {
            (2, width / 2)
        } else {
            (3, width)
        };
        out[codes_at + i / 4] |= code << (2 * (i % 4));
        out.extend_from_slice(&d.to_le_bytes()[..bytes]);
    }
    out
}

/// `TfFastCompression`: a chunk count byte (0 for a single block), then
/// LZ4 blocks; more than one block only past LZ4's input limit, each then
/// preceded by its compressed size.
pub(super) fn fast_compress(input: &[u8]) -> Vec<u8> {
    if input.len() <= LZ4_MAX_INPUT_SIZE {
        let mut out = vec![0u8];
        out.extend_from_slice(&lz4_flex::block::compress(input));
        return out;
    }
    let chunks = input.chunks(LZ4_MAX_INPUT_SIZE);
    let mut out = vec![chunks.len() as u8];
    for chunk in chunks {
        let block = lz4_flex::block::compress(chunk);
        out.extend_from_slice(&(block.len() as i32).to_le_bytes());
        out.extend_from_slice(&block);
    }
    out
}

/// Integers as a compressed crate array body: the compressed size, then
/// the LZ4-framed coding.
pub(super) fn compressed_integers(
    values: impl ExactSizeIterator<Item = i64> + Clone,
    wide: bool,
) -> Vec<u8> {
    let compressed = fast_compress(&encode_integers(values, wide));
    let mut out = Vec::with_capacity(8 + compressed.len());
    out.extend_from_slice(&(compressed.len() as u64).to_le_bytes());
    out.extend_from_slice(&compressed);
    out
}

/// Distinct values a float lookup table holds at most: enough for any
/// ramp along a hair, small enough to stay in cache.
const MAX_TABLE: usize = 1024;

/// A float array with few distinct values (widths along a hair, the same
/// ramp on every hair), as OpenUSD's writer compresses them: the code
/// `t`, a lookup table of the distinct values (bit patterns kept) and
/// each value's index as compressed integers. `None` when more than a
/// quarter of the values (or more than [`MAX_TABLE`]) are distinct, where
/// a table does not pay.
pub(super) fn float_lookup_table(values: &[f32]) -> Option<Vec<u8>> {
    let limit = (values.len() / 4).min(MAX_TABLE);
    // Blocks find their distinct values in parallel; the table lists them
    // in the order of first appearance, as one pass would, so the bytes
    // do not depend on the threads.
    let blocks: Vec<(Vec<u32>, Vec<u32>)> = values
        .par_chunks(1 << 18)
        .map(|block| local_table(block, limit))
        .collect::<Option<_>>()?;
    let mut table = SmallTable::default();
    let mut remaps: Vec<Vec<u32>> = Vec::with_capacity(blocks.len());
    for (distinct, _) in &blocks {
        let mut remap = Vec::with_capacity(distinct.len());
        for &bits in distinct {
            remap.push(table.index(bits));
            if table.values.len() > limit {
                return None;
            }
        }
        remaps.push(remap);
    }
    let mut indices = Vec::with_capacity(values.len());
    for ((_, local), remap) in blocks.iter().zip(&remaps) {
        indices.extend(local.iter().map(|&i| remap[i as usize]));
    }
    let mut out = Vec::with_capacity(5 + 4 * table.values.len() + values.len() / 2);
    out.push(b't');
    out.extend_from_slice(&(table.values.len() as u32).to_le_bytes());
    for bits in &table.values {
        out.extend_from_slice(&bits.to_le_bytes());
    }
    out.extend(compressed_integers(
        indices.iter().map(|&i| i as i64),
        false,
    ));
    Some(out)
}

/// A block's distinct bit patterns (first appearance first) and each
/// value's index among them; `None` past `limit` distinct values.
fn local_table(block: &[f32], limit: usize) -> Option<(Vec<u32>, Vec<u32>)> {
    let mut table = SmallTable::default();
    let mut indices = Vec::with_capacity(block.len());
    for v in block {
        indices.push(table.index(v.to_bits()));
        if table.values.len() > limit {
            return None;
        }
    }
    Some((table.values, indices))
}

/// Distinct `u32`s in order of appearance, found by open addressing (4
/// slots per value the table may hold, so a probe ends in a step or two).
struct SmallTable {
    values: Vec<u32>,
    slots: Vec<(u32, u32)>,
}

impl Default for SmallTable {
    fn default() -> Self {
        Self {
            values: Vec::new(),
            slots: vec![(0, u32::MAX); 4 * (MAX_TABLE + 1)],
        }
    }
}

impl SmallTable {
    /// The index of `bits`, added if new. Holds [`MAX_TABLE`] + 1 values;
    /// callers stop before more.
    fn index(&mut self, bits: u32) -> u32 {
        let n = self.slots.len();
        let mut slot = (bits.wrapping_mul(0x9e37_79b9) >> 16) as usize % n;
        loop {
            match self.slots[slot] {
                (_, u32::MAX) => {
                    let i = self.values.len() as u32;
                    self.values.push(bits);
                    self.slots[slot] = (bits, i);
                    return i;
                }
                (b, i) if b == bits => return i,
                _ => slot = (slot + 1) % n,
            }
        }
    }
}

/// A writer that knows how many bytes it has written (the offsets values
/// are recorded at), without asking the file.
pub(super) struct Counted<W> {
    pub inner: W,
    pub position: u64,
}

impl<W: Write> Write for Counted<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.position += n as u64;
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.inner.flush()
    }
}

/// One node of the layer's path tree: the pseudo-root, a prim, or a
/// property of a prim.
struct PathNode {
    /// Token of the last path element (unused for the root).
    element: u32,
    property: bool,
    children: Vec<u32>,
}

/// A spec: a path, its kind, and its fields as (name token, value).
pub(super) struct Spec {
    pub path: u32,
    pub kind: SpecType,
    pub fields: Vec<(u32, ValueRep)>,
}

/// The structure of a layer, kept in memory while values stream to the
/// file: tokens, strings, the path tree and the specs.
pub(super) struct Structure {
    tokens: Vec<String>,
    token_ids: HashMap<String, u32>,
    strings: Vec<u32>,
    paths: Vec<PathNode>,
    pub specs: Vec<Spec>,
}

/// The pseudo-root's path index.
pub(super) const ROOT_PATH: u32 = 0;

impl Structure {
    /// A structure with the pseudo-root path only. `first_token` becomes
    /// token 0: a prim name, since a property path marks its element token
    /// by negating the index and so cannot use token 0.
    pub fn new(first_token: &str) -> Self {
        let mut structure = Self {
            tokens: Vec::new(),
            token_ids: HashMap::new(),
            strings: Vec::new(),
            paths: vec![PathNode {
                element: 0,
                property: false,
                children: Vec::new(),
            }],
            specs: Vec::new(),
        };
        structure.token(first_token);
        structure
    }

    /// The index of `token`, added if new.
    pub fn token(&mut self, token: &str) -> u32 {
        if let Some(&id) = self.token_ids.get(token) {
            return id;
        }
        let id = self.tokens.len() as u32;
        self.tokens.push(token.to_string());
        self.token_ids.insert(token.to_string(), id);
        id
    }

    /// The index of a new string (strings are stored as tokens).
    pub fn string(&mut self, text: &str) -> u32 {
        let token = self.token(text);
        self.strings.push(token);
        self.strings.len() as u32 - 1
    }

    /// A new path: `name` under `parent`, a property or a prim.
    pub fn child_path(&mut self, parent: u32, name: &str, property: bool) -> u32 {
        let element = self.token(name);
        debug_assert!(!property || element != 0);
        let id = self.paths.len() as u32;
        self.paths.push(PathNode {
            element,
            property,
            children: Vec::new(),
        });
        self.paths[parent as usize].children.push(id);
        id
    }

    /// Writes the six sections and the table of contents; returns the
    /// table's offset.
    pub fn write_sections<W: Write>(&self, out: &mut Counted<W>) -> io::Result<u64> {
        let mut toc: Vec<(&str, u64, u64)> = Vec::new();
        let mut section = |out: &mut Counted<W>, name, bytes: Vec<u8>| {
            toc.push((name, out.position, bytes.len() as u64));
            out.write_all(&bytes)
        };
        section(out, "TOKENS", self.tokens_section())?;
        section(out, "STRINGS", self.strings_section())?;
        let (fields, fieldsets, starts) = self.fields_and_sets();
        section(out, "FIELDS", fields)?;
        section(out, "FIELDSETS", fieldsets)?;
        section(out, "PATHS", self.paths_section())?;
        section(out, "SPECS", self.specs_section(&starts))?;
        let toc_offset = out.position;
        out.write_all(&(toc.len() as u64).to_le_bytes())?;
        for (name, start, size) in toc {
            let mut padded = [0u8; 16];
            padded[..name.len()].copy_from_slice(name.as_bytes());
            out.write_all(&padded)?;
            out.write_all(&start.to_le_bytes())?;
            out.write_all(&size.to_le_bytes())?;
        }
        Ok(toc_offset)
    }

    /// Token count, then the NUL-terminated tokens, uncompressed size and
    /// LZ4-framed.
    fn tokens_section(&self) -> Vec<u8> {
        let mut text = Vec::new();
        for token in &self.tokens {
            text.extend_from_slice(token.as_bytes());
            text.push(0);
        }
        let compressed = fast_compress(&text);
        let mut out = Vec::new();
        for n in [self.tokens.len(), text.len(), compressed.len()] {
            out.extend_from_slice(&(n as u64).to_le_bytes());
        }
        out.extend_from_slice(&compressed);
        out
    }

    /// String count, then each string's token index.
    fn strings_section(&self) -> Vec<u8> {
        let mut out = (self.strings.len() as u64).to_le_bytes().to_vec();
        for s in &self.strings {
            out.extend_from_slice(&s.to_le_bytes());
        }
        out
    }

    /// The fields table (distinct (name, value) pairs: names compressed as
    /// integers, values LZ4-framed) and the field sets (each spec's field
    /// indices, ended by `u32::MAX`); also where each spec's set starts.
    fn fields_and_sets(&self) -> (Vec<u8>, Vec<u8>, Vec<u32>) {
        let mut fields: Vec<(u32, ValueRep)> = Vec::new();
        let mut field_ids: HashMap<(u32, ValueRep), u32> = HashMap::new();
        let mut sets: Vec<u32> = Vec::new();
        let mut starts = Vec::with_capacity(self.specs.len());
        for spec in &self.specs {
            starts.push(sets.len() as u32);
            for &field in &spec.fields {
                let id = *field_ids.entry(field).or_insert_with(|| {
                    fields.push(field);
                    fields.len() as u32 - 1
                });
                sets.push(id);
            }
            sets.push(u32::MAX);
        }
        let mut table = (fields.len() as u64).to_le_bytes().to_vec();
        table.extend(compressed_integers(
            fields.iter().map(|f| f.0 as i64),
            false,
        ));
        let reps: Vec<u8> = fields.iter().flat_map(|f| f.1.0.to_le_bytes()).collect();
        let reps = fast_compress(&reps);
        table.extend_from_slice(&(reps.len() as u64).to_le_bytes());
        table.extend_from_slice(&reps);
        let mut set_bytes = (sets.len() as u64).to_le_bytes().to_vec();
        set_bytes.extend(compressed_integers(sets.iter().map(|&s| s as i64), false));
        (table, set_bytes, starts)
    }

    /// The path tree in depth-first order: for each node its path index,
    /// its element token (negated for a property) and a jump: -2 a leaf
    /// with no next sibling, -1 a first child follows and no sibling, 0 a
    /// sibling follows and no child, n > 0 a child follows and the next
    /// sibling is n entries on.
    fn paths_section(&self) -> Vec<u8> {
        let n = self.paths.len();
        let (mut indices, mut elements, mut jumps) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        self.visit(ROOT_PATH, false, &mut indices, &mut elements, &mut jumps);
        let mut out = (n as u64).to_le_bytes().to_vec();
        out.extend_from_slice(&(indices.len() as u64).to_le_bytes());
        out.extend(compressed_integers(
            indices.iter().map(|&i: &u32| i as i64),
            false,
        ));
        out.extend(compressed_integers(
            elements.iter().map(|&e: &i32| e as i64),
            false,
        ));
        out.extend(compressed_integers(
            jumps.iter().map(|&j: &i32| j as i64),
            false,
        ));
        out
    }

    fn visit(
        &self,
        node: u32,
        has_sibling: bool,
        indices: &mut Vec<u32>,
        elements: &mut Vec<i32>,
        jumps: &mut Vec<i32>,
    ) {
        let at = indices.len();
        let path = &self.paths[node as usize];
        indices.push(node);
        elements.push(if path.property {
            -(path.element as i32)
        } else {
            path.element as i32
        });
        jumps.push(0);
        for (k, &child) in path.children.iter().enumerate() {
            self.visit(child, k + 1 < path.children.len(), indices, elements, jumps);
        }
        jumps[at] = match (path.children.is_empty(), has_sibling) {
            (true, false) => -2,
            (false, false) => -1,
            (true, true) => 0,
            (false, true) => (indices.len() - at) as i32,
        };
    }

    /// Spec count, then compressed path indices, field-set starts and
    /// spec types.
    fn specs_section(&self, starts: &[u32]) -> Vec<u8> {
        let mut out = (self.specs.len() as u64).to_le_bytes().to_vec();
        out.extend(compressed_integers(
            self.specs.iter().map(|s| s.path as i64),
            false,
        ));
        out.extend(compressed_integers(starts.iter().map(|&s| s as i64), false));
        out.extend(compressed_integers(
            self.specs.iter().map(|s| s.kind as u32 as i64),
            false,
        ));
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The decoder of `integerCoding.cpp`, for the round trip.
    fn decode(bytes: &[u8], count: usize, wide: bool) -> Vec<i64> {
        let width = if wide { 8 } else { 4 };
        let read = |at: usize, n: usize| {
            let mut b = [0u8; 8];
            b[..n].copy_from_slice(&bytes[at..at + n]);
            // Sign-extend from n bytes.
            (i64::from_le_bytes(b) << (64 - 8 * n)) >> (64 - 8 * n)
        };
        let common = read(0, width);
        let codes = width;
        let mut at = width + count.div_ceil(4);
        let mut previous = 0i64;
        (0..count)
            .map(|i| {
                let code = (bytes[codes + i / 4] >> (2 * (i % 4))) & 3;
                let n = [0, width / 4, width / 2, width][code as usize];
                let delta = if n == 0 { common } else { read(at, n) };
                at += n;
                previous = if wide {
                    previous.wrapping_add(delta)
                } else {
                    (previous as i32).wrapping_add(delta as i32) as i64
                };
                previous
            })
            .collect()
    }

    #[test]
    fn integer_coding_round_trips_small_large_and_negative_steps() {
        let narrow: Vec<i64> = vec![16, 16, 16, 16, 3, -200, 70_000, i32::MAX as i64, 0, 5];
        let bytes = encode_integers(narrow.iter().copied(), false);
        assert_eq!(decode(&bytes, narrow.len(), false), narrow);
        let wide: Vec<i64> = vec![1, 2, 3, 1 << 40, -(1 << 33), 7, 7, 7];
        let bytes = encode_integers(wide.iter().copied(), true);
        assert_eq!(decode(&bytes, wide.len(), true), wide);
    }

    #[test]
    fn few_distinct_floats_become_a_table_and_many_stay_plain() {
        let ramp: Vec<f32> = (0..64)
            .map(|i| [0.5, 0.25, -0.0, f32::MIN_POSITIVE][i % 4])
            .collect();
        let body = float_lookup_table(&ramp).unwrap();
        assert_eq!(body[0], b't');
        assert_eq!(u32::from_le_bytes(body[1..5].try_into().unwrap()), 4);
        let table: Vec<f32> = body[5..21]
            .chunks(4)
            .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
            .collect();
        assert_eq!(
            table[2].to_bits(),
            (-0.0f32).to_bits(),
            "bit patterns are kept"
        );
        let compressed = u64::from_le_bytes(body[21..29].try_into().unwrap()) as usize;
        let coded =
            lz4_flex::block::decompress(&body[30..30 + compressed - 1], 4 + 16 + 64).unwrap();
        let indices = decode(&coded, 64, false);
        let back: Vec<f32> = indices.iter().map(|&i| table[i as usize]).collect();
        assert!(
            back.iter()
                .zip(&ramp)
                .all(|(a, b)| a.to_bits() == b.to_bits())
        );
        let distinct: Vec<f32> = (0..64).map(|i| i as f32 * 0.1).collect();
        assert!(float_lookup_table(&distinct).is_none());
    }

    #[test]
    fn a_constant_step_costs_two_bits_a_value() {
        let ids: Vec<i64> = (0..1000).collect();
        let bytes = encode_integers(ids.iter().copied(), false);
        assert_eq!(
            bytes.len(),
            4 + 250 + 1,
            "common step 1, then one 1-byte first delta… {}",
            bytes.len()
        );
    }
}
