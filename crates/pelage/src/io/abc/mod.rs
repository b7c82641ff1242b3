//! Alembic (Ogawa) curves output, streamed: one `ICurves` object per part,
//! with positions, vertex counts, widths and normals as the `AbcGeom_Curve_v2`
//! schema names them, and colour, hair id and root UV as arbitrary geometry
//! parameters under the names Unreal's groom importer reads (`groom_color`,
//! `groom_id`, `groom_root_uv`), so the file goes straight into a game
//! engine as well as into Blender, Houdini or Maya; hair-shading values
//! (`hair_melanin`, …) are arbitrary parameters per curve under the USD
//! primvars' names.
//!
//! Arrays are written to the file as each part arrives; the groups that
//! list them (a few hundred bytes a part) are written at
//! [`AbcWriter::finish`]. Parts written frame by frame
//! ([`AbcWriter::write_part_at`]) get a sample of `P`, `N` and the bounds
//! per frame on one time sampling (seconds = time code / frames per second).
//!
//! The layout follows Alembic's `AbcCoreOgawa` (`AwImpl`, `OwData`,
//! `CpwData`, `ApwImpl`, `SpwImpl`, `WriteUtil`) and `AbcGeom` (`OCurves`,
//! `OGeomParam`); the keys of samples are MurmurHash3 digests as Alembic's,
//! the properties' and children's digests in each object's headers are
//! pelage's own (readers do not check them).

mod ogawa;
mod read;

pub use read::{
    AbcCurvesObject, abc_curves_from_bytes, read_abc_curves, read_abc_curves_at,
    read_abc_description, read_abc_objects, read_abc_sample_count,
};

use super::usd_options::check_name;
use super::usd_schema::curve_extent;
use super::{CurveBasis, PrimWriteError, UsdOptions};
use crate::{Curves, Mesh};
use ogawa::{Child, EMPTY_DATA, EMPTY_GROUP, OgawaWriter, murmur3_128};
use std::collections::HashSet;
use std::io::{Seek, Write};

/// Alembic's plain old data types (`Alembic::Util::PlainOldDataType`).
#[derive(Debug, Clone, Copy)]
#[repr(u8)]
enum Pod {
    Uint8 = 1,
    Int32 = 6,
    Int64 = 8,
    Float32 = 10,
    Float64 = 11,
}

impl Pod {
    fn name(self) -> &'static str {
        match self {
            Pod::Uint8 => "uint8_t",
            Pod::Int32 => "int32_t",
            Pod::Int64 => "int64_t",
            Pod::Float32 => "float32_t",
            Pod::Float64 => "float64_t",
        }
    }
}

/// Per-point (`vtx`), per-curve (`uni`) or per-corner (`fvr`) geometry
/// parameters.
#[derive(Debug, Clone, Copy)]
enum Scope {
    Vertex,
    Uniform,
    FaceVarying,
}

#[derive(Debug)]
enum Kind {
    Compound(Vec<Property>),
    Scalar,
    Array,
}

/// A property and the samples written so far (data blocks, and for
/// arrays their element counts).
#[derive(Debug)]
struct Property {
    name: String,
    metadata: String,
    kind: Kind,
    pod: Pod,
    extent: u8,
    /// 0: the default sampling (one static sample); 1: the frames.
    time_sampling: u32,
    samples: Vec<Sample>,
}

/// A sample: its data block, and its element count.
type Sample = (Child, usize);

impl Property {
    fn compound(name: &str, metadata: &str, children: Vec<Property>) -> Self {
        Self {
            name: name.into(),
            metadata: metadata.into(),
            kind: Kind::Compound(children),
            pod: Pod::Uint8,
            extent: 0,
            time_sampling: 0,
            samples: Vec::new(),
        }
    }

    /// The child property named `name`, of a compound.
    fn child(&mut self, name: &str) -> Option<&mut Property> {
        match &mut self.kind {
            Kind::Compound(children) => children.iter_mut().find(|c| c.name == name),
            _ => None,
        }
    }
}

/// One object (a part's curves, or the skin): its `.geom` compound, its
/// schema's object metadata, and what later frames must match (curve
/// offsets; a mesh's vertex and triangle counts).
struct Part {
    name: String,
    object: &'static str,
    geom: Property,
    offsets: Vec<u32>,
    times: Vec<f64>,
}

/// Streams an Alembic file: [`AbcWriter::new`], then any number of
/// [`write_part`](Self::write_part) / [`write_part_at`](Self::write_part_at),
/// then [`finish`](Self::finish).
pub struct AbcWriter<W: Write + Seek> {
    ogawa: OgawaWriter<W>,
    options: UsdOptions,
    parts: Vec<Part>,
    names: HashSet<String>,
}

/// The curves schema's object and compound metadata.
const CURVES_OBJECT: &str = "schema=AbcGeom_Curve_v2;schemaBaseType=AbcGeom_GeomBase_v1;schemaObjTitle=AbcGeom_Curve_v2:.geom";
const CURVES_GEOM: &str = "schema=AbcGeom_Curve_v2;schemaBaseType=AbcGeom_GeomBase_v1";
/// The polygon mesh schema's (the skin).
const MESH_OBJECT: &str = "schema=AbcGeom_PolyMesh_v1;schemaBaseType=AbcGeom_GeomBase_v1;schemaObjTitle=AbcGeom_PolyMesh_v1:.geom";
const MESH_GEOM: &str = "schema=AbcGeom_PolyMesh_v1;schemaBaseType=AbcGeom_GeomBase_v1";
/// What Alembic's `ALEMBIC_OGAWA_FILE_VERSION` and library version say.
const OGAWA_FILE_VERSION: i32 = 0;
const LIBRARY_VERSION: i32 = 10_800;
/// Alembic's time per cycle for samples at arbitrary times.
const ACYCLIC_TIME_PER_CYCLE: f64 = f64::MAX / 32.0;

impl<W: Write + Seek> AbcWriter<W> {
    /// Starts the file. The curve basis, the root name (unused: Alembic
    /// objects sit under the archive's top object) and the frames per
    /// second come from `options`.
    pub fn new(out: W, options: &UsdOptions) -> Result<Self, PrimWriteError> {
        options.check()?;
        Ok(Self {
            ogawa: OgawaWriter::new(out)?,
            options: options.clone(),
            parts: Vec::new(),
            names: HashSet::new(),
        })
    }

    /// Writes one part as an `ICurves` object named `name`.
    pub fn write_part(&mut self, name: &str, curves: &Curves) -> Result<(), PrimWriteError> {
        self.start_part(name, curves, None)
    }

    /// Writes one frame of an animated part: the first call for `name`
    /// writes the object (vertex counts, widths, colours, ids from this
    /// frame); every call adds a sample of `P`, `N` and the bounds at
    /// `time` (in frames). Frames come in increasing time, with the same
    /// curves; every animated part has the same frames.
    pub fn write_part_at(
        &mut self,
        name: &str,
        time: f64,
        curves: &Curves,
    ) -> Result<(), PrimWriteError> {
        self.write_curves_at(name, time, curves, false)
    }

    /// Writes one frame of animated guides, as [`Self::write_part_at`]
    /// does for a part, on an object flagged as [`Self::write_guides`]
    /// flags it.
    pub fn write_guides_at(
        &mut self,
        name: &str,
        time: f64,
        guides: &Curves,
    ) -> Result<(), PrimWriteError> {
        self.write_curves_at(name, time, guides, true)
    }

    /// [`Self::write_part_at`], or with `guide` [`Self::write_guides_at`]
    /// (the object flagged `groom_guide`).
    fn write_curves_at(
        &mut self,
        name: &str,
        time: f64,
        curves: &Curves,
        guide: bool,
    ) -> Result<(), PrimWriteError> {
        PrimWriteError::check_time(name, time)?;
        let what = if guide { "guides" } else { "part" };
        let Some(index) = self.next_frame(what, name, time)? else {
            return self.start_part_as(name, curves, Some(time), guide);
        };
        PrimWriteError::check_frame(name, time, &self.parts[index].offsets, curves)?;
        let samples = self.animated_samples(curves)?;
        self.push_frame(index, time, samples);
        Ok(())
    }

    /// The index of the animated object `name` a frame at `time` goes to
    /// (`None`: not written yet). Refuses an object written still, and a
    /// frame not after its last one (`what`, "part" or "mesh", says which
    /// in the message).
    fn next_frame(
        &self,
        what: &str,
        name: &str,
        time: f64,
    ) -> Result<Option<usize>, PrimWriteError> {
        let Some(index) = self.parts.iter().position(|p| p.name == name) else {
            return Ok(None);
        };
        let Some(&last) = self.parts[index].times.last() else {
            return Err(PrimWriteError::DuplicateName(name.to_string()));
        };
        if time <= last {
            return Err(PrimWriteError::BadSetting(format!(
                "{what} {name:?}: frame at {time} after the frame at {last}; write frames in increasing time"
            )));
        }
        Ok(Some(index))
    }

    /// Adds one frame's samples (by property name under `.geom`) to the
    /// object at `index`.
    fn push_frame(&mut self, index: usize, time: f64, samples: Vec<(&str, Sample)>) {
        let part = &mut self.parts[index];
        for (name, sample) in samples {
            if let Some(property) = part.geom.child(name) {
                property.samples.push(sample);
            }
        }
        part.times.push(time);
    }

    /// The samples of the animated properties for one frame, by path
    /// under `.geom`.
    fn animated_samples(
        &mut self,
        curves: &Curves,
    ) -> std::io::Result<Vec<(&'static str, Sample)>> {
        let mut samples = vec![
            (".selfBnds", self.bounds_sample(curve_extent(curves))?),
            (
                "P",
                self.array_sample(bytemuck::cast_slice(curves.points()), curves.points().len())?,
            ),
        ];
        if let Some(normals) = curves.normals() {
            let sample = self.array_sample(bytemuck::cast_slice(normals), normals.len())?;
            samples.push(("N", sample));
        }
        if let Some(velocities) = curves.velocities() {
            let sample = self.array_sample(bytemuck::cast_slice(velocities), velocities.len())?;
            samples.push((".velocities", sample));
        }
        Ok(samples)
    }

    /// A box's sample (`.selfBnds`): its corners as six doubles.
    fn bounds_sample(&mut self, (lo, hi): (glam::Vec3, glam::Vec3)) -> std::io::Result<Sample> {
        let bounds: Vec<u8> = [lo.x, lo.y, lo.z, hi.x, hi.y, hi.z]
            .iter()
            .flat_map(|&v| f64::from(v).to_le_bytes())
            .collect();
        self.array_sample(&bounds, 1)
    }

    /// Takes `name` for an object of the archive.
    fn claim(&mut self, name: &str) -> Result<(), PrimWriteError> {
        check_name(name)?;
        if !self.names.insert(name.to_string()) {
            return Err(PrimWriteError::DuplicateName(name.to_string()));
        }
        Ok(())
    }

    /// A sample's data block: its key (MurmurHash3 of the bytes), then the
    /// bytes, little-endian; an empty array is an empty block.
    fn array_sample(&mut self, bytes: &[u8], points: usize) -> std::io::Result<Sample> {
        if bytes.is_empty() {
            return Ok((EMPTY_DATA, 0));
        }
        let key = murmur3_128(bytes);
        Ok((self.ogawa.data(&[&key, bytes])?, points))
    }

    /// Writes the groom's guide curves as an `ICurves` object named
    /// `name`, flagged `groom_guide = 1` (with their regions as
    /// `groom_group_id`): what Unreal's groom importer simulates and
    /// interpolates from.
    pub fn write_guides(&mut self, name: &str, guides: &Curves) -> Result<(), PrimWriteError> {
        self.start_part_as(name, guides, None, true)
    }

    fn start_part(
        &mut self,
        name: &str,
        curves: &Curves,
        time: Option<f64>,
    ) -> Result<(), PrimWriteError> {
        self.start_part_as(name, curves, time, false)
    }

    fn start_part_as(
        &mut self,
        name: &str,
        curves: &Curves,
        time: Option<f64>,
        guide: bool,
    ) -> Result<(), PrimWriteError> {
        self.claim(name)?;
        let min = self.options.min_points_per_curve();
        if let Some(curve) = (0..curves.curve_count()).find(|&i| curves.range(i).len() < min) {
            return Err(PrimWriteError::ShortCurve {
                part: name.to_string(),
                curve,
                points: curves.range(curve).len(),
                min,
                basis: "Catmull-Rom",
            });
        }
        let frames = time.is_some() as u32;
        let animated = self.animated_samples(curves)?;
        let take = |name: &str| -> Vec<Sample> {
            animated
                .iter()
                .find(|(n, _)| *n == name)
                .map(|(_, s)| vec![*s])
                .unwrap_or_default()
        };
        let bounds = take(".selfBnds");
        let points = take("P");
        let normals = take("N");
        let velocities = take(".velocities");
        let mut properties = vec![
            property(
                ".selfBnds",
                "interpretation=box",
                Kind::Scalar,
                Pod::Float64,
                6,
                frames,
                bounds,
            ),
            property(
                "P",
                "geoScope=vtx;interpretation=vector",
                Kind::Array,
                Pod::Float32,
                3,
                frames,
                points,
            ),
        ];
        if !velocities.is_empty() {
            // ICurves' velocities: one a point, units a second.
            properties.push(property(
                ".velocities",
                "geoScope=vtx;interpretation=vector",
                Kind::Array,
                Pod::Float32,
                3,
                frames,
                velocities,
            ));
        }
        let counts: Vec<u8> = curves
            .offsets()
            .windows(2)
            .flat_map(|w| ((w[1] - w[0]) as i32).to_le_bytes())
            .collect();
        let sample = self.array_sample(&counts, curves.curve_count())?;
        properties.push(property(
            "nVertices",
            "",
            Kind::Array,
            Pod::Int32,
            1,
            0,
            vec![sample],
        ));
        let basis_and_type = match self.options.basis {
            // type linear, non-periodic, no basis
            CurveBasis::Linear => [1u8, 0, 0, 0],
            // type cubic, non-periodic, Catmull-Rom
            CurveBasis::CatmullRom => [0u8, 0, 3, 3],
        };
        let sample = self.array_sample(&basis_and_type, 1)?;
        properties.push(property(
            "curveBasisAndType",
            "",
            Kind::Scalar,
            Pod::Uint8,
            4,
            0,
            vec![sample],
        ));
        let widths = bytemuck::cast_slice(curves.widths());
        let sample = self.array_sample(widths, curves.widths().len())?;
        properties.push(geom_param(
            "width",
            Scope::Vertex,
            "",
            Pod::Float32,
            1,
            0,
            vec![sample],
        ));
        if !normals.is_empty() {
            properties.push(geom_param(
                "N",
                Scope::Vertex,
                "normal",
                Pod::Float32,
                3,
                frames,
                normals,
            ));
        }
        let arbitrary = self.arbitrary_params(curves, guide)?;
        if !arbitrary.is_empty() {
            properties.push(Property::compound(".arbGeomParams", "", arbitrary));
        }
        self.parts.push(Part {
            name: name.to_string(),
            object: CURVES_OBJECT,
            geom: Property::compound(".geom", CURVES_GEOM, properties),
            offsets: curves.offsets().to_vec(),
            times: time.into_iter().collect(),
        });
        Ok(())
    }

    /// A part's `.arbGeomParams`: colours, opacities, ids, regions (Unreal's
    /// groom groups), the guide flag, root UVs and the hair-shading values,
    /// each where the curves have it.
    fn arbitrary_params(
        &mut self,
        curves: &Curves,
        guide: bool,
    ) -> Result<Vec<Property>, PrimWriteError> {
        let mut arbitrary = Vec::new();
        if let Some(colors) = curves.colors() {
            let sample = self.array_sample(bytemuck::cast_slice(colors), colors.len())?;
            arbitrary.push(geom_param(
                "groom_color",
                Scope::Vertex,
                "rgb",
                Pod::Float32,
                3,
                0,
                vec![sample],
            ));
        }
        if let Some(opacities) = curves.opacities() {
            let sample = self.array_sample(bytemuck::cast_slice(opacities), opacities.len())?;
            arbitrary.push(geom_param(
                "groom_opacity",
                Scope::Vertex,
                "",
                Pod::Float32,
                1,
                0,
                vec![sample],
            ));
        }
        if let Some(ids) = curves.ids() {
            let (bytes, pod): (Vec<u8>, Pod) = if ids.iter().all(|&id| id <= i32::MAX as u64) {
                (
                    ids.iter()
                        .flat_map(|&id| (id as i32).to_le_bytes())
                        .collect(),
                    Pod::Int32,
                )
            } else {
                (
                    ids.iter()
                        .flat_map(|&id| (id as i64).to_le_bytes())
                        .collect(),
                    Pod::Int64,
                )
            };
            let sample = self.array_sample(&bytes, ids.len())?;
            arbitrary.push(geom_param(
                "groom_id",
                Scope::Uniform,
                "",
                pod,
                1,
                0,
                vec![sample],
            ));
        }
        if let Some(regions) = curves.regions() {
            // Unreal's groom groups: one a region, guides matched to hairs
            // by it.
            let sample = self.array_sample(bytemuck::cast_slice(regions), regions.len())?;
            arbitrary.push(geom_param(
                "groom_group_id",
                Scope::Uniform,
                "",
                Pod::Int32,
                1,
                0,
                vec![sample],
            ));
        }
        if guide {
            let ones: Vec<u8> = std::iter::repeat_n(1i32.to_le_bytes(), curves.curve_count())
                .flatten()
                .collect();
            let sample = self.array_sample(&ones, curves.curve_count())?;
            arbitrary.push(geom_param(
                "groom_guide",
                Scope::Uniform,
                "",
                Pod::Int32,
                1,
                0,
                vec![sample],
            ));
        }
        if let Some(uvs) = curves.root_uvs() {
            let sample = self.array_sample(bytemuck::cast_slice(uvs), uvs.len())?;
            arbitrary.push(geom_param(
                "groom_root_uv",
                Scope::Uniform,
                "vector",
                Pod::Float32,
                2,
                0,
                vec![sample],
            ));
        }
        if let Some(shading) = curves.shading() {
            // Under the USD primvars' names: Blender's importer makes them
            // the same curve attributes its USD importer does.
            for (name, values) in shading.floats() {
                let sample = self.array_sample(bytemuck::cast_slice(values), values.len())?;
                arbitrary.push(geom_param(
                    name,
                    Scope::Uniform,
                    "",
                    Pod::Float32,
                    1,
                    0,
                    vec![sample],
                ));
            }
            let tint = &shading.tint;
            let sample = self.array_sample(bytemuck::cast_slice(tint), tint.len())?;
            arbitrary.push(geom_param(
                crate::curves::HairShading::TINT,
                Scope::Uniform,
                "rgb",
                Pod::Float32,
                3,
                0,
                vec![sample],
            ));
        }
        Ok(arbitrary)
    }

    /// Writes the skin as an `IPolyMesh` object named `name`: positions,
    /// triangles and UVs (`uv`, per vertex or per corner as the mesh has
    /// them).
    pub fn write_mesh(&mut self, name: &str, mesh: &Mesh) -> Result<(), PrimWriteError> {
        self.start_mesh(name, mesh, None)
    }

    /// Writes one frame of an animated skin: the first call for `name`
    /// writes the object (triangles and UVs from this frame); every call
    /// adds a sample of `P` and the bounds at `time`. Later frames have as
    /// many vertices and triangles, on the frames the parts have.
    pub fn write_mesh_at(
        &mut self,
        name: &str,
        time: f64,
        mesh: &Mesh,
    ) -> Result<(), PrimWriteError> {
        PrimWriteError::check_time(name, time)?;
        let Some(index) = self.next_frame("mesh", name, time)? else {
            return self.start_mesh(name, mesh, Some(time));
        };
        if self.parts[index].object != MESH_OBJECT {
            return Err(PrimWriteError::DuplicateName(name.to_string()));
        }
        PrimWriteError::check_mesh_frame(name, time, &self.parts[index].offsets, mesh)?;
        let (bounds, points) = self.mesh_samples(mesh)?;
        self.push_frame(index, time, vec![(".selfBnds", bounds), ("P", points)]);
        Ok(())
    }

    /// A mesh's bounds and positions samples.
    fn mesh_samples(&mut self, mesh: &Mesh) -> std::io::Result<(Sample, Sample)> {
        let bounds = self.bounds_sample(mesh.bounds())?;
        let positions = mesh.positions();
        let points = self.array_sample(bytemuck::cast_slice(positions), positions.len())?;
        Ok((bounds, points))
    }

    fn start_mesh(
        &mut self,
        name: &str,
        mesh: &Mesh,
        time: Option<f64>,
    ) -> Result<(), PrimWriteError> {
        self.claim(name)?;
        let frames = time.is_some() as u32;
        let (bounds, points) = self.mesh_samples(mesh)?;
        // Alembic's faces wind clockwise (as Maya's); pelage's wind
        // counter-clockwise: each triangle is written as (a, c, b), and
        // per-corner values in the same order. Readers (Blender's among
        // them) turn them back.
        let corners = |t: &[u32; 3]| [t[0], t[2], t[1]];
        let indices: Vec<u8> = mesh
            .triangles()
            .iter()
            .flat_map(corners)
            .flat_map(|i| (i as i32).to_le_bytes())
            .collect();
        let counts: Vec<u8> = std::iter::repeat_n(3i32.to_le_bytes(), mesh.triangle_count())
            .flatten()
            .collect();
        let indices = self.array_sample(&indices, mesh.triangle_count() * 3)?;
        let counts = self.array_sample(&counts, mesh.triangle_count())?;
        let mut properties = vec![
            property(
                ".selfBnds",
                "interpretation=box",
                Kind::Scalar,
                Pod::Float64,
                6,
                frames,
                vec![bounds],
            ),
            property(
                "P",
                "geoScope=vtx;interpretation=point",
                Kind::Array,
                Pod::Float32,
                3,
                frames,
                vec![points],
            ),
            property(
                ".faceIndices",
                "",
                Kind::Array,
                Pod::Int32,
                1,
                0,
                vec![indices],
            ),
            property(
                ".faceCounts",
                "",
                Kind::Array,
                Pod::Int32,
                1,
                0,
                vec![counts],
            ),
        ];
        let uvs = match mesh.uvs() {
            None => None,
            Some(crate::mesh::Uvs::PerVertex(uvs)) => Some((Scope::Vertex, uvs.clone())),
            Some(crate::mesh::Uvs::PerCorner { values, indices }) => Some((
                Scope::FaceVarying,
                indices
                    .iter()
                    .flat_map(corners)
                    .map(|i| values[i as usize])
                    .collect(),
            )),
        };
        if let Some((scope, uvs)) = uvs {
            let sample = self.array_sample(bytemuck::cast_slice(&uvs), uvs.len())?;
            properties.push(geom_param(
                "uv",
                scope,
                "vector",
                Pod::Float32,
                2,
                0,
                vec![sample],
            ));
        }
        self.parts.push(Part {
            name: name.to_string(),
            object: MESH_OBJECT,
            geom: Property::compound(".geom", MESH_GEOM, properties),
            offsets: vec![mesh.vertex_count() as u32, mesh.triangle_count() as u32],
            times: time.into_iter().collect(),
        });
        Ok(())
    }

    /// Writes the groups of every part, the top object, the time
    /// samplings and the archive's metadata; returns the output (not
    /// flushed), positioned at its end.
    pub fn finish(mut self) -> Result<W, PrimWriteError> {
        let frames = self.frame_times()?;
        let mut objects = Vec::with_capacity(self.parts.len());
        let mut headers = Vec::new();
        for part in std::mem::take(&mut self.parts) {
            let geom = self.write_compound_group(&part.geom)?;
            let geom_header = property_header(&part.geom);
            let header_data = self.ogawa.data(&[&geom_header])?;
            let properties = self.ogawa.group(&[geom, header_data])?;
            // No children: the headers block is the two digests alone.
            let digests = self.ogawa.data(&[&object_digests(&part.geom)])?;
            objects.push(self.ogawa.group(&[properties, digests])?);
            headers.extend_from_slice(&(part.name.len() as u32).to_le_bytes());
            headers.extend_from_slice(part.name.as_bytes());
            headers.push(0xff);
            headers.extend_from_slice(&(part.object.len() as u32).to_le_bytes());
            headers.extend_from_slice(part.object.as_bytes());
        }
        headers.extend_from_slice(&murmur3_128(&headers));
        headers.extend_from_slice(&[0u8; 16]);
        let mut top = vec![EMPTY_GROUP];
        top.extend_from_slice(&objects);
        top.push(self.ogawa.data(&[&headers])?);
        let top = self.ogawa.group(&top)?;

        let mut samplings = Vec::new();
        // Index 0, the default: one sample a second from time 0.
        samplings.extend_from_slice(&1u32.to_le_bytes());
        samplings.extend_from_slice(&1.0f64.to_le_bytes());
        samplings.extend_from_slice(&1u32.to_le_bytes());
        samplings.extend_from_slice(&0.0f64.to_le_bytes());
        if let Some(times) = &frames {
            let per_second = self.options.time_codes_per_second;
            let seconds: Vec<f64> = times.iter().map(|t| t / per_second).collect();
            let step = seconds.get(1).map_or(1.0 / per_second, |s| s - seconds[0]);
            let uniform = seconds
                .windows(2)
                .all(|w| ((w[1] - w[0]) - step).abs() <= 1e-9 * step.abs().max(1.0));
            samplings.extend_from_slice(&(times.len() as u32).to_le_bytes());
            if uniform {
                samplings.extend_from_slice(&step.to_le_bytes());
                samplings.extend_from_slice(&1u32.to_le_bytes());
                samplings.extend_from_slice(&seconds[0].to_le_bytes());
            } else {
                samplings.extend_from_slice(&ACYCLIC_TIME_PER_CYCLE.to_le_bytes());
                samplings.extend_from_slice(&(seconds.len() as u32).to_le_bytes());
                for s in &seconds {
                    samplings.extend_from_slice(&s.to_le_bytes());
                }
            }
        }
        let metadata = format!(
            "_ai_AlembicVersion=Alembic 1.8.0 (written by pelage {v});_ai_Application=pelage {v};_ai_Description={d}",
            v = env!("CARGO_PKG_VERSION"),
            d = self
                .options
                .documentation
                .as_deref()
                .unwrap_or("hair curves"),
        );
        let root = [
            self.ogawa.data(&[&OGAWA_FILE_VERSION.to_le_bytes()])?,
            self.ogawa.data(&[&LIBRARY_VERSION.to_le_bytes()])?,
            top,
            self.ogawa.data(&[metadata.as_bytes()])?,
            self.ogawa.data(&[&samplings])?,
            // No indexed metadata: every header carries its own.
            EMPTY_DATA,
        ];
        let root = self.ogawa.group(&root)?;
        Ok(self.ogawa.finish(root)?)
    }

    /// The frames every animated part shares, if any part is animated.
    fn frame_times(&self) -> Result<Option<Vec<f64>>, PrimWriteError> {
        let mut animated = self.parts.iter().filter(|p| !p.times.is_empty());
        let Some(first) = animated.next() else {
            return Ok(None);
        };
        for other in animated {
            if other.times != first.times {
                return Err(PrimWriteError::BadSetting(format!(
                    "parts {:?} and {:?} have different frames; in Alembic every animated part has the same frames",
                    first.name, other.name
                )));
            }
        }
        Ok(Some(first.times.clone()))
    }

    /// A compound's group: each child's group, then the block of their
    /// headers.
    fn write_compound_group(&mut self, compound: &Property) -> std::io::Result<Child> {
        let Kind::Compound(children) = &compound.kind else {
            unreachable!("called on compounds")
        };
        let mut groups = Vec::with_capacity(children.len() + 1);
        let mut headers = Vec::new();
        for child in children {
            groups.push(match &child.kind {
                Kind::Compound(_) => self.write_compound_group(child)?,
                // A scalar's samples; an array's samples each followed by
                // its dimensions (empty: a 1-D array's length follows
                // from the block's size).
                Kind::Scalar => self
                    .ogawa
                    .group(&child.samples.iter().map(|s| s.0).collect::<Vec<_>>())?,
                Kind::Array => self.ogawa.group(
                    &child
                        .samples
                        .iter()
                        .flat_map(|s| [s.0, EMPTY_DATA])
                        .collect::<Vec<_>>(),
                )?,
            });
            headers.extend(property_header(child));
        }
        if !headers.is_empty() {
            groups.push(self.ogawa.data(&[&headers])?);
        }
        self.ogawa.group(&groups)
    }
}

/// A plain (scalar or array) property.
#[allow(clippy::too_many_arguments)]
fn property(
    name: &str,
    metadata: &str,
    kind: Kind,
    pod: Pod,
    extent: u8,
    time_sampling: u32,
    samples: Vec<Sample>,
) -> Property {
    Property {
        name: name.into(),
        metadata: metadata.into(),
        kind,
        pod,
        extent,
        time_sampling,
        samples,
    }
}

fn geom_param(
    name: &str,
    scope: Scope,
    interpretation: &str,
    pod: Pod,
    extent: u8,
    time_sampling: u32,
    samples: Vec<Sample>,
) -> Property {
    let scope = match scope {
        Scope::Vertex => "vtx",
        Scope::Uniform => "uni",
        Scope::FaceVarying => "fvr",
    };
    let interpretation = if interpretation.is_empty() {
        String::new()
    } else {
        format!("interpretation={interpretation};")
    };
    Property {
        name: name.into(),
        metadata: format!(
            "arrayExtent=1;geoScope={scope};{interpretation}isGeomParam=true;podExtent={extent};podName={}",
            pod.name()
        ),
        kind: Kind::Array,
        pod,
        extent,
        time_sampling,
        samples,
    }
}

/// A property's header as `WritePropertyInfo` packs it: an info word
/// (kind, size hint, type, sampling flags, extent, metadata inline), the
/// sample count and time sampling where needed, the name and the metadata,
/// sizes in 1, 2 or 4 bytes as the longest of them needs.
fn property_header(property: &Property) -> Vec<u8> {
    let samples = property.samples.len() as u32;
    let longest = [
        property.metadata.len() as u32,
        property.name.len() as u32,
        samples,
        property.time_sampling,
    ]
    .into_iter()
    .max()
    .unwrap_or(0);
    let hint: u32 = match longest {
        0..=255 => 0,
        256..=65_535 => 1,
        _ => 2,
    };
    let sized = |v: u32, out: &mut Vec<u8>| {
        out.extend_from_slice(&v.to_le_bytes()[..[1, 2, 4][hint as usize]]);
    };
    let metadata_index: u32 = if property.metadata.is_empty() {
        0
    } else {
        0xff
    };
    let mut info = (hint << 2) | (metadata_index << 20);
    let mut out = Vec::new();
    if let Kind::Compound(_) = property.kind {
        out.extend_from_slice(&info.to_le_bytes());
    } else {
        let scalar_like = property.samples.iter().all(|s| s.1 == 1);
        let homogenous = property.samples.windows(2).all(|w| w[0].1 == w[1].1);
        let kind = match property.kind {
            Kind::Scalar => 1,
            _ => 2,
        };
        info |= kind | scalar_like as u32;
        info |= (property.pod as u32) << 4;
        if property.time_sampling != 0 {
            info |= 0x100;
        }
        // Every sample written differs from the one before: the first
        // change is sample 1 and the last is the last; one sample is a
        // constant.
        if samples <= 1 {
            info |= 0x800;
        }
        if homogenous {
            info |= 0x400;
        }
        info |= (property.extent as u32) << 12;
        out.extend_from_slice(&info.to_le_bytes());
        sized(samples, &mut out);
        if property.time_sampling != 0 {
            sized(property.time_sampling, &mut out);
        }
    }
    sized(property.name.len() as u32, &mut out);
    out.extend_from_slice(property.name.as_bytes());
    if metadata_index == 0xff {
        sized(property.metadata.len() as u32, &mut out);
        out.extend_from_slice(property.metadata.as_bytes());
    }
    out
}

/// The digests of an object's properties and children that end its
/// headers block: pelage's own, from the properties' sample keys.
fn object_digests(geom: &Property) -> [u8; 32] {
    fn keys(p: &Property, into: &mut Vec<u8>) {
        into.extend_from_slice(p.name.as_bytes());
        for s in &p.samples {
            into.extend_from_slice(&s.0.to_le_bytes());
        }
        if let Kind::Compound(children) = &p.kind {
            children.iter().for_each(|c| keys(c, into));
        }
    }
    let mut all = Vec::new();
    keys(geom, &mut all);
    let mut out = [0u8; 32];
    out[..16].copy_from_slice(&murmur3_128(&all));
    out
}

impl<W: Write + Seek> super::PrimWriter for AbcWriter<W> {
    fn write_part(&mut self, name: &str, curves: &Curves) -> Result<(), PrimWriteError> {
        AbcWriter::write_part(self, name, curves)
    }

    fn write_mesh(&mut self, name: &str, mesh: &Mesh) -> Result<(), PrimWriteError> {
        AbcWriter::write_mesh(self, name, mesh)
    }

    fn write_mesh_at(&mut self, name: &str, time: f64, mesh: &Mesh) -> Result<(), PrimWriteError> {
        AbcWriter::write_mesh_at(self, name, time, mesh)
    }

    /// Alembic files from pelage hold curves and the skin.
    fn write_points(
        &mut self,
        _name: &str,
        _points: &super::SurfacePoints,
    ) -> Result<(), PrimWriteError> {
        Err(PrimWriteError::BadSetting(
            "pelage's Alembic files hold curves and the skin: write sampled points as .ply or USD"
                .into(),
        ))
    }

    fn write_part_at(
        &mut self,
        name: &str,
        time: f64,
        curves: &Curves,
    ) -> Result<(), PrimWriteError> {
        AbcWriter::write_part_at(self, name, time, curves)
    }

    fn write_guides(&mut self, name: &str, guides: &Curves) -> Result<(), PrimWriteError> {
        AbcWriter::write_guides(self, name, guides)
    }

    fn write_guides_at(
        &mut self,
        name: &str,
        time: f64,
        guides: &Curves,
    ) -> Result<(), PrimWriteError> {
        AbcWriter::write_guides_at(self, name, time, guides)
    }
}
