//! Every salt that keeps one random stream apart from another. A stream is
//! keyed by `(seed ^ SALT, index)` ([`super::SampleRng`]), so two features
//! drawing with the same user seed and hair id still get unrelated numbers
//! as long as their salts differ. The values are part of the output: a
//! changed salt changes every groom that uses it, so they live here, named,
//! and a test checks that no two are equal. Each groom operator keeps its
//! own salts in its module (`groom/ops/<name>.rs`); the test compares
//! those too.

/// Part `p`'s roots: `mix64(seed ^ mix64(PART_ROOTS + p))`.
pub const PART_ROOTS: u64 = 0x9A27;
/// Shell fur: droplets scattered over a mesh.
pub const DROPLETS: u64 = 0x5EED_D201;

/// Cell `c`'s hair arrivals (stable ids): `mix64(seed ^ mix64(CELL_ARRIVALS + c))`.
pub const CELL_ARRIVALS: u64 = 0x0CE1_1A77;
/// Cell `c`'s roots (stable ids): `mix64(seed ^ mix64(CELL_ROOTS + c))`.
pub const CELL_ROOTS: u64 = 0xCE11_2007;
/// Blue-noise roots: the candidates a part's roots are chosen from.
pub const BLUE_NOISE: u64 = 0xB10E_2015;

/// `[look]`: a hair's melanin jitter.
pub const LOOK_MELANIN: u64 = 0x100C_3E1A;
/// `[look]`: a hair's melanin redness jitter.
pub const LOOK_REDNESS: u64 = 0x100C_4ED0;
/// `[look]`: a hair's roughness jitter.
pub const LOOK_ROUGHNESS: u64 = 0x100C_2006;
/// `[look]`: a hair's radial roughness jitter.
pub const LOOK_RADIAL_ROUGHNESS: u64 = 0x100C_2AD1;
/// `[look]`: a hair's `hair_random`.
pub const LOOK_RANDOM: u64 = 0x100C_0AA0;

/// Every salt above, with its name.
pub const ALL: [(&str, u64); 10] = [
    ("PART_ROOTS", PART_ROOTS),
    ("DROPLETS", DROPLETS),
    ("CELL_ARRIVALS", CELL_ARRIVALS),
    ("CELL_ROOTS", CELL_ROOTS),
    ("BLUE_NOISE", BLUE_NOISE),
    ("LOOK_MELANIN", LOOK_MELANIN),
    ("LOOK_REDNESS", LOOK_REDNESS),
    ("LOOK_ROUGHNESS", LOOK_ROUGHNESS),
    ("LOOK_RADIAL_ROUGHNESS", LOOK_RADIAL_ROUGHNESS),
    ("LOOK_RANDOM", LOOK_RANDOM),
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_two_streams_share_a_salt() {
        let mut all: Vec<(String, u64)> = ALL.iter().map(|(n, s)| (n.to_string(), *s)).collect();
        all.extend(crate::groom::ops::operator_salts());
        assert!(all.len() > ALL.len(), "the operators' salts are counted");
        for (i, (a, x)) in all.iter().enumerate() {
            for (b, y) in &all[i + 1..] {
                assert_ne!(
                    x, y,
                    "{a} and {b} share a salt: their streams would coincide"
                );
            }
        }
    }
}
