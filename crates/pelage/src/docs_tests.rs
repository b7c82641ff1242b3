//! The docs' tables of defaults held to the code: each test reads a
//! table of a page in docs/ and compares its default column with the
//! defaults the code has.

/// The default column of `key`'s row in the table under `heading` of a
/// page in docs/.
pub(crate) fn documented_default(page: &str, heading: &str, key: &str) -> String {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../docs")
        .join(page);
    let text = std::fs::read_to_string(&path).unwrap();
    let section = text
        .split(heading)
        .nth(1)
        .unwrap_or_else(|| panic!("{}: no heading {heading}", path.display()));
    let row = section
        .lines()
        .find(|l| l.starts_with(&format!("| `{key}` |")))
        .unwrap_or_else(|| panic!("{page} {heading}: no row for {key}"));
    row.split('|').nth(2).unwrap().trim().to_string()
}

/// [`documented_default`] read as a number.
pub(crate) fn documented_number(page: &str, heading: &str, key: &str) -> f32 {
    let cell = documented_default(page, heading, key);
    cell.parse()
        .unwrap_or_else(|_| panic!("{page} {key}: {cell:?} is not a number"))
}

#[test]
fn the_parameters_table_says_the_librarys_defaults() {
    let default =
        |key: &str| documented_number("dynamics.md", "### Parameters (`GuideStrandParams`)", key);
    let p = crate::dynamics::GuideStrandParams::default();
    assert_eq!(default("substeps"), p.substeps as f32);
    assert_eq!(default("iterations"), p.iterations as f32);
    assert_eq!(default("damping"), p.damping);
    assert_eq!(default("bend"), p.bend);
    assert_eq!(default("follow"), p.follow);
    assert_eq!(default("ftl_damping"), p.ftl_damping);
    assert_eq!(default("thickness"), p.thickness);
    assert_eq!(default("friction"), p.friction);
}
