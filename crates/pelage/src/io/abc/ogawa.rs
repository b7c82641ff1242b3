//! Ogawa, the container under Alembic: a tree of groups (lists of child
//! positions) and data blocks (a size and bytes), written bottom-up so
//! that every child is in the file before the group that lists it. The
//! layout is Alembic's `lib/Alembic/Ogawa` (`OStream`, `OGroup`):
//!
//! - a 16-byte header: `Ogawa`, a byte that becomes `0xff` once the file
//!   is complete, the format version (0, 1), and the root group's offset;
//! - a data block: its size as `u64`, then its bytes; a group: its child
//!   count as `u64`, then a `u64` per child — a data block's offset with
//!   the top bit set, or a group's offset; an empty data block is the top
//!   bit alone and an empty group is 0.

use std::io::{self, Seek, SeekFrom, Write};

/// A child of a group: where a data block or group is, as groups list it.
pub(super) type Child = u64;

/// The top bit marks data; alone, it is an empty data block.
pub(super) const EMPTY_DATA: Child = 1 << 63;
/// An empty group.
pub(super) const EMPTY_GROUP: Child = 0;

const HEADER_SIZE: u64 = 16;

/// Writes an Ogawa file bottom-up: [`data`](Self::data) and
/// [`group`](Self::group) return the [`Child`] to list in a parent;
/// [`finish`](Self::finish) names the root and marks the file complete.
pub(super) struct OgawaWriter<W: Write + Seek> {
    out: W,
    /// Where the file starts in `out`.
    start: u64,
    /// Bytes written since `start`.
    position: u64,
}

impl<W: Write + Seek> OgawaWriter<W> {
    /// Writes the header of an incomplete file.
    pub fn new(mut out: W) -> io::Result<Self> {
        let start = out.stream_position()?;
        out.write_all(b"Ogawa\0\0\x01")?;
        out.write_all(&0u64.to_le_bytes())?;
        Ok(Self {
            out,
            start,
            position: HEADER_SIZE,
        })
    }

    /// A data block made of `parts` one after another.
    pub fn data(&mut self, parts: &[&[u8]]) -> io::Result<Child> {
        let size: usize = parts.iter().map(|p| p.len()).sum();
        if size == 0 {
            return Ok(EMPTY_DATA);
        }
        let at = self.position;
        self.out.write_all(&(size as u64).to_le_bytes())?;
        for part in parts {
            self.out.write_all(part)?;
        }
        self.position += 8 + size as u64;
        Ok(at | EMPTY_DATA)
    }

    /// A group listing `children`.
    pub fn group(&mut self, children: &[Child]) -> io::Result<Child> {
        if children.is_empty() {
            return Ok(EMPTY_GROUP);
        }
        let at = self.position;
        self.out.write_all(&(children.len() as u64).to_le_bytes())?;
        let bytes: Vec<u8> = children.iter().flat_map(|c| c.to_le_bytes()).collect();
        self.out.write_all(&bytes)?;
        self.position += 8 * (1 + children.len() as u64);
        Ok(at)
    }

    /// Names `root` the root group and marks the file complete; returns
    /// the output positioned at its end.
    pub fn finish(mut self, root: Child) -> io::Result<W> {
        self.out.seek(SeekFrom::Start(self.start + 5))?;
        self.out.write_all(&[0xff])?;
        self.out.seek(SeekFrom::Start(self.start + 8))?;
        self.out.write_all(&root.to_le_bytes())?;
        self.out.seek(SeekFrom::Start(self.start + self.position))?;
        Ok(self.out)
    }
}

/// MurmurHash3 x64-128 (Austin Appleby, public domain), the hash Alembic
/// keys array samples with; readers use the 16-byte key to recognise
/// equal samples, so distinct data must get distinct keys.
pub(super) fn murmur3_128(data: &[u8]) -> [u8; 16] {
    const C1: u64 = 0x87c3_7b91_1142_53d5;
    const C2: u64 = 0x4cf5_ad43_2745_937f;
    let fmix = |mut k: u64| {
        k ^= k >> 33;
        k = k.wrapping_mul(0xff51_afd7_ed55_8ccd);
        k ^= k >> 33;
        k = k.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
        k ^ (k >> 33)
    };
    let (mut h1, mut h2) = (0u64, 0u64);
    let blocks = data.chunks_exact(16);
    let tail = blocks.remainder();
    for block in blocks {
        let k1 = u64::from_le_bytes(block[..8].try_into().expect("8 bytes"));
        let k2 = u64::from_le_bytes(block[8..].try_into().expect("8 bytes"));
        h1 ^= k1.wrapping_mul(C1).rotate_left(31).wrapping_mul(C2);
        h1 = h1
            .rotate_left(27)
            .wrapping_add(h2)
            .wrapping_mul(5)
            .wrapping_add(0x52dc_e729);
        h2 ^= k2.wrapping_mul(C2).rotate_left(33).wrapping_mul(C1);
        h2 = h2
            .rotate_left(31)
            .wrapping_add(h1)
            .wrapping_mul(5)
            .wrapping_add(0x3849_5ab5);
    }
    let mut padded = [0u8; 16];
    padded[..tail.len()].copy_from_slice(tail);
    let k1 = u64::from_le_bytes(padded[..8].try_into().expect("8 bytes"));
    let k2 = u64::from_le_bytes(padded[8..].try_into().expect("8 bytes"));
    if tail.len() > 8 {
        h2 ^= k2.wrapping_mul(C2).rotate_left(33).wrapping_mul(C1);
    }
    if !tail.is_empty() {
        h1 ^= k1.wrapping_mul(C1).rotate_left(31).wrapping_mul(C2);
    }
    h1 ^= data.len() as u64;
    h2 ^= data.len() as u64;
    h1 = h1.wrapping_add(h2);
    h2 = h2.wrapping_add(h1);
    h1 = fmix(h1);
    h2 = fmix(h2);
    h1 = h1.wrapping_add(h2);
    h2 = h2.wrapping_add(h1);
    let mut out = [0u8; 16];
    out[..8].copy_from_slice(&h1.to_le_bytes());
    out[8..].copy_from_slice(&h2.to_le_bytes());
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn murmur3_matches_the_reference_vectors() {
        // From the reference implementation (seed 0).
        assert_eq!(murmur3_128(b""), [0; 16]);
        let h = murmur3_128(b"hello");
        assert_eq!(
            u64::from_le_bytes(h[..8].try_into().unwrap()),
            0xcbd8_a7b3_41bd_9b02
        );
        let h = murmur3_128(b"The quick brown fox jumps over the lazy dog");
        assert_eq!(
            u64::from_le_bytes(h[..8].try_into().unwrap()),
            0xe34b_bc7b_bc07_1b6c
        );
    }

    #[test]
    fn groups_list_their_children_and_the_header_names_the_root() {
        let mut w = OgawaWriter::new(std::io::Cursor::new(Vec::new())).unwrap();
        let d = w.data(&[b"ab", b"c"]).unwrap();
        assert_eq!(d, 16 | EMPTY_DATA);
        assert_eq!(w.data(&[b""]).unwrap(), EMPTY_DATA);
        let g = w.group(&[d, EMPTY_GROUP]).unwrap();
        let bytes = w.finish(g).unwrap().into_inner();
        assert_eq!(&bytes[..8], b"Ogawa\xff\0\x01");
        assert_eq!(u64::from_le_bytes(bytes[8..16].try_into().unwrap()), g);
        assert_eq!(&bytes[16..27], b"\x03\0\0\0\0\0\0\0abc");
        assert_eq!(u64::from_le_bytes(bytes[27..35].try_into().unwrap()), 2);
    }
}
