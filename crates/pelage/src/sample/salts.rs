//! Every salt that keeps one random stream apart from another. A stream is
//! keyed by `(seed ^ SALT, index)` ([`super::SampleRng`]), so two features
//! drawing with the same user seed and hair id still get unrelated numbers
//! as long as their salts differ. The values are part of the output: a
//! changed salt changes every groom that uses it, so they live here, named,
//! and a test checks that no two are equal.

/// Part `p`'s roots: `mix64(seed ^ mix64(PART_ROOTS + p))`.
pub const PART_ROOTS: u64 = 0x9A27;
/// `width`'s per-hair jitter.
pub const WIDTH_JITTER: u64 = 0x3D_7714;
/// `opacity`'s per-hair jitter.
pub const OPACITY_JITTER: u64 = 0x00BA_C17E;
/// `color`'s per-hair brightness jitter.
pub const COLOR_JITTER: u64 = 0xC0_10E;
/// `length`'s per-hair jitter.
pub const LENGTH_JITTER: u64 = 0x1E_4674;
/// `strands`: where each strand hair sits around its base hair.
pub const STRAND_SPREAD: u64 = 0x57_2A4D;
/// `frizz`: the noise field it follows.
pub const FRIZZ_FIELD: u64 = 0xF122;
/// `frizz`: whether a hair frizzes, and its offset into the field.
pub const FRIZZ_HAIR: u64 = 0xF122_F122;
/// `curl`: each hair's phase.
pub const CURL_PHASE: u64 = 0xC0_11;
/// Shell fur: droplets scattered over a mesh.
pub const DROPLETS: u64 = 0x5EED_D201;

/// Cell `c`'s hair arrivals (stable ids): `mix64(seed ^ mix64(CELL_ARRIVALS + c))`.
pub const CELL_ARRIVALS: u64 = 0x0CE1_1A77;
/// Cell `c`'s roots (stable ids): `mix64(seed ^ mix64(CELL_ROOTS + c))`.
pub const CELL_ROOTS: u64 = 0xCE11_2007;
/// Blue-noise roots: the candidates a part's roots are chosen from.
pub const BLUE_NOISE: u64 = 0xB10E_2015;

/// Every salt above, with its name.
pub const ALL: [(&str, u64); 13] = [
    ("PART_ROOTS", PART_ROOTS),
    ("WIDTH_JITTER", WIDTH_JITTER),
    ("OPACITY_JITTER", OPACITY_JITTER),
    ("COLOR_JITTER", COLOR_JITTER),
    ("LENGTH_JITTER", LENGTH_JITTER),
    ("STRAND_SPREAD", STRAND_SPREAD),
    ("FRIZZ_FIELD", FRIZZ_FIELD),
    ("FRIZZ_HAIR", FRIZZ_HAIR),
    ("CURL_PHASE", CURL_PHASE),
    ("DROPLETS", DROPLETS),
    ("CELL_ARRIVALS", CELL_ARRIVALS),
    ("CELL_ROOTS", CELL_ROOTS),
    ("BLUE_NOISE", BLUE_NOISE),
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_two_streams_share_a_salt() {
        for (i, (a, x)) in ALL.iter().enumerate() {
            for (b, y) in &ALL[i + 1..] {
                assert_ne!(
                    x, y,
                    "{a} and {b} share a salt: their streams would coincide"
                );
            }
        }
    }
}
