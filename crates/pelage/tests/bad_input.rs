//! The malformed-input corpus (`tests/data/bad/`, made by its
//! `make_corpus.py`): every file gives a typed error that names the file,
//! the line or element where there is one, and what is wrong; none panics.

use pelage::Mesh;
use pelage::map::{Channel, ImageMap, Wrap};
use pelage::mesh::MeshFormat;
use std::path::{Path, PathBuf};

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/bad")
}

/// Loads a corpus file with the loader its extension calls for and returns
/// the error message.
fn error_of(file: &str) -> String {
    let path = corpus().join(file);
    let message = match path.extension().and_then(|e| e.to_str()) {
        Some("png" | "exr") => ImageMap::load(&path, Channel::Luminance, Wrap::Repeat)
            .err()
            .map(|e| e.to_string()),
        _ => Mesh::load(&path).err().map(|e| e.to_string()),
    };
    message.unwrap_or_else(|| panic!("{file} loaded without an error"))
}

/// (file, where — appended to the path — and what the message must say)
const CASES: &[(&str, &str, &str)] = &[
    (
        "obj_index_zero.obj",
        ":5: ",
        "vertex index 0 is out of range: there are 3 vertices; OBJ indices start at 1",
    ),
    (
        "obj_index_past_end.obj",
        ":5: ",
        "vertex index 9 is out of range: there are 3 vertices",
    ),
    (
        "obj_negative_index_past_start.obj",
        ":4: ",
        "vertex index -4 is out of range",
    ),
    (
        "obj_nan_vertex.obj",
        ":2: ",
        "vertex position has a non-finite value",
    ),
    (
        "obj_inf_vertex.obj",
        ":2: ",
        "1e39 is too large: coordinates are 32-bit floats",
    ),
    (
        "obj_bad_number.obj",
        ":2: ",
        "cannot read \"abc\" as a number",
    ),
    (
        "obj_too_few_coordinates.obj",
        ":2: ",
        "a vertex (v x y z) needs 3 numbers, found 2",
    ),
    (
        "obj_two_vertex_face.obj",
        ":4: ",
        "a face needs at least 3 vertices, this one has 2",
    ),
    ("obj_empty.obj", ": ", "the mesh is empty: no vertices"),
    ("obj_no_faces.obj", ": ", "the mesh is empty: no faces"),
    (
        "obj_mixed_uvs.obj",
        ":9: ",
        "this face has no texture coordinates (vt) and the faces before it (from line 8) have them",
    ),
    (
        "obj_uv_index_past_end.obj",
        ":5: ",
        "uv index 5 is out of range: there is 1 uv",
    ),
    ("obj_not_text.obj", ":5: ", "not valid UTF-8"),
    (
        "ply_wrong_magic.ply",
        ":1: ",
        "not a readable PLY file: Expected magic number 'ply'",
    ),
    ("ply_unknown_format.ply", ":2: ", "not a readable PLY file"),
    (
        "ply_truncated_binary.ply",
        ": ",
        "the file ends before all the elements its header announces (truncated?): \
         Unexpected end of file while reading binary element 'vertex' (expected 8, got 3)",
    ),
    (
        "ply_face_index_out_of_range.ply",
        ": face 1: ",
        "vertex index 7 is out of range: there are 3 vertices",
    ),
    ("ply_nan_ascii.ply", ":11: ", "String: '1 nan 0'"),
    (
        "ply_nan_binary.ply",
        ": vertex 1: ",
        "vertex position has a non-finite value",
    ),
    ("ply_bad_token.ply", ":11: ", "String: '1 zero 0'"),
    (
        "ply_no_face_element.ply",
        ": ",
        "the file has no 'face' element",
    ),
    (
        "ply_no_x_property.ply",
        ": ",
        "the 'vertex' element has no 'x' property",
    ),
    ("gltf_not_json.gltf", ": ", "not a readable glTF file"),
    ("glb_truncated.glb", ": ", "not a readable glTF file"),
    (
        "gltf_accessor_past_buffer.gltf",
        ": ",
        "accessor 0 reaches past the end of its buffer view",
    ),
    ("png_not_a_png.png", ": ", "not a readable PNG or EXR image"),
    ("png_truncated.png", ": ", "not a readable PNG or EXR image"),
    (
        "exr_not_an_exr.exr",
        ": ",
        "not a readable PNG or EXR image",
    ),
    (
        "mesh_unknown_extension.stl",
        ": ",
        "unknown mesh format \"stl\"; pelage reads .obj, .ply, .gltf, .glb, .usda, .usdc and .usd",
    ),
];

#[test]
fn every_bad_file_names_itself_where_and_what() {
    let mut failures = Vec::new();
    for (file, location, what) in CASES {
        let message = error_of(file);
        let expected_start = format!("{}{location}", corpus().join(file).display());
        if !message.starts_with(&expected_start) || !message.contains(what) {
            failures.push(format!(
                "{file}:\n  got      {message}\n  expected {expected_start}…{what}…"
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn every_file_in_the_corpus_has_a_case() {
    let mut files: Vec<String> = std::fs::read_dir(corpus())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|f| f != "make_corpus.py")
        .collect();
    files.sort();
    assert!(
        files.len() >= 15,
        "the corpus should hold at least 15 files"
    );
    for f in &files {
        assert!(
            CASES.iter().any(|(c, _, _)| c == f),
            "{f} has no case in CASES"
        );
    }
}

#[test]
fn missing_file_names_the_file() {
    let err = Mesh::load("no/such/mesh.obj").unwrap_err().to_string();
    assert!(
        err.starts_with("no/such/mesh.obj: cannot read the file:"),
        "{err}"
    );
}

/// Cutting a valid file anywhere must give an error or a smaller valid
/// mesh, never a panic.
#[test]
fn truncated_files_never_panic() {
    let obj = pelage::assets::SPOT_OBJ;
    for k in 1..64 {
        let cut = obj.len() * k / 64;
        let _ = Mesh::from_bytes("cut.obj", &obj[..cut], MeshFormat::Obj);
    }
    let ply = binary_ply_of(&pelage::assets::spot());
    for k in 0..200 {
        let cut = ply.len() * k / 200;
        let result = Mesh::from_bytes("cut.ply", &ply[..cut], MeshFormat::Ply);
        assert!(
            result.is_err(),
            "a binary PLY cut at byte {cut} of {} loaded",
            ply.len()
        );
    }
    assert!(Mesh::from_bytes("whole.ply", &ply, MeshFormat::Ply).is_ok());
}

fn binary_ply_of(mesh: &Mesh) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\n\
         property float y\nproperty float z\nelement face {}\n\
         property list uchar int vertex_indices\nend_header\n",
        mesh.vertex_count(),
        mesh.triangle_count()
    )
    .into_bytes();
    for p in mesh.positions() {
        for c in p.to_array() {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    for t in mesh.triangles() {
        out.push(3);
        for i in t {
            out.extend_from_slice(&(*i as i32).to_le_bytes());
        }
    }
    out
}
