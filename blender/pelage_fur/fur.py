"""Blender meshes in, pelage grooms grown, Blender hair curves out.

pelage is imported where it is used, so that ``curves_to_blender`` also
serves scripts (and pelage's benchmark) that only have arrays.

Everything here moves data in bulk (``foreach_get`` / ``foreach_set`` with
numpy arrays): no Python loop runs per point or curve, so a million
hairs become a Curves object in about a second. Vertex-group weights are
the one exception (Blender has no bulk accessor for them): one pass over
the mesh's vertices, only when the object has vertex groups.

The Curves object is what Blender's own hair tools make: points in the
surface object's space, ``radius`` per point, ``surface_uv_coordinate`` per
curve with ``surface`` and ``surface_uv_map`` set, so Blender's "Deform
Curves on Surface" node carries the fur when the mesh is animated.
"""

import numpy as np

#: Attribute names on the created curves.
HAIR_ID = "hair_id"
COLOR = "color"
#: pelage's per-hair shader values (``Curves.shading``), per curve; the
#: USD writer's primvars have the same names, so Blender's USD importer
#: brings a pelage file's values in as these attributes too.
SHADING_FLOATS = ("hair_melanin", "hair_melanin_redness", "hair_roughness",
                  "hair_radial_roughness", "hair_random")
TINT = "hair_tint"
#: The material that reads them.
HAIR_MATERIAL = "pelage hair"


#: Blender's world is Z-up, pelage's (its gravity, its combs) Y-up, as USD's
#: default: (x, y, z) in Blender is (x, z, -y) in pelage.
Z_UP_TO_Y_UP = np.array([[1, 0, 0], [0, 0, 1], [0, -1, 0]], dtype=np.float64)


def to_pelage_space(obj):
    """The 4×4 matrix from ``obj``'s local space to pelage's Y-up world:
    the object's world matrix, then Z-up to Y-up. Gravity and combs then
    point where they would in any Y-up DCC, whatever the object's
    rotation."""
    world = np.array(obj.matrix_world, dtype=np.float64)
    to_y_up = np.eye(4)
    to_y_up[:3, :3] = Z_UP_TO_Y_UP
    return to_y_up @ world


def transform_points(matrix, points):
    """``points`` (n, 3) through the affine 4×4 ``matrix``, as float32
    (computed in float32: a live groom moves a million points a stroke)."""
    m = np.asarray(matrix, dtype=np.float32)
    p = np.asarray(points, dtype=np.float32)
    return p @ m[:3, :3].T + m[:3, 3]


def use_rest_positions(obj):
    """Asks Blender to keep ``obj``'s vertices as they are before shape
    keys and modifiers (armature included) in its evaluated mesh, as the
    ``rest_position`` attribute: the rest pose that Deform Curves on
    Surface carries the fur from, and the one pelage grows on."""
    if not obj.add_rest_position_attribute:
        obj.add_rest_position_attribute = True


def mesh_to_pelage(obj, depsgraph, rest=False):
    """The evaluated mesh of ``obj`` (modifiers applied), triangulated, as a
    ``pelage.Mesh`` in pelage's Y-up world (``to_pelage_space``), with the
    active UV map's UVs per triangle corner. Returns ``(mesh, uv_map_name
    or None)``.

    With ``rest``, the vertices are the rest pose where Blender keeps one
    (``use_rest_positions``): where they were before the armature and the
    shape keys moved them, at whatever frame the scene is on. Fur grown
    there is what Deform Curves on Surface expects; fur grown on a posed
    frame would be deformed twice."""
    import pelage

    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        mesh.calc_loop_triangles()
        positions = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
        rest_positions = mesh.attributes.get("rest_position") if rest else None
        if rest_positions is not None:
            rest_positions.data.foreach_get("vector", positions)
        else:
            mesh.vertices.foreach_get("co", positions)
        positions = transform_points(to_pelage_space(obj), positions.reshape(-1, 3))
        count = len(mesh.loop_triangles)
        if count == 0:
            raise pelage.PelageError(f"{obj.name}: the mesh has no faces to grow fur on")
        triangles = np.empty(count * 3, dtype=np.int32)
        mesh.loop_triangles.foreach_get("vertices", triangles)
        uv_layer = mesh.uv_layers.active
        corner_uvs = None
        if uv_layer is not None:
            loops = np.empty(count * 3, dtype=np.int32)
            mesh.loop_triangles.foreach_get("loops", loops)
            uvs = np.empty(len(mesh.loops) * 2, dtype=np.float32)
            uv_layer.data.foreach_get("uv", uvs)
            corner_uvs = uvs.reshape(-1, 2)[loops]
        result = pelage.Mesh.from_arrays(
            positions.reshape(-1, 3),
            triangles.reshape(-1, 3),
            uvs=corner_uvs,
            name=obj.name,
            vertex_maps=vertex_maps_of(obj, mesh),
            **face_sets_of(mesh, parting_attribute(obj)),
        )
        return result, (uv_layer.name if uv_layer is not None else None)
    finally:
        evaluated.to_mesh_clear()


def vertex_maps_of(obj, mesh):
    """The object's vertex groups, the mesh's float point attributes and
    its colour attributes (by channel), by name, one float32 a vertex:
    what a groom reads as ``"vertex:NAME"`` maps (density, lengths,
    masks). Vertex groups have no bulk accessor
    in Blender's Python API, so their weights take one Python pass over
    the vertices (only when the object has vertex groups)."""
    count = len(mesh.vertices)
    maps = {}
    if obj.vertex_groups:
        weights = np.zeros((len(obj.vertex_groups), count), dtype=np.float32)
        for vertex in mesh.vertices:
            for element in vertex.groups:
                if element.group < len(weights):
                    weights[element.group, vertex.index] = element.weight
        for group in obj.vertex_groups:
            maps[group.name] = weights[group.index]
    corner_vertex = None
    for attribute in mesh.attributes:
        if attribute.name.startswith(".") or attribute.name in maps:
            continue
        if attribute.domain == "POINT" and attribute.data_type == "FLOAT":
            values = np.empty(count, dtype=np.float32)
            attribute.data.foreach_get("value", values)
            maps[attribute.name] = values
        elif attribute.data_type in ("FLOAT_COLOR", "BYTE_COLOR") and attribute.domain in ("POINT", "CORNER"):
            # Colour attributes (Vertex Paint's): each channel a map,
            # NAME:r, NAME:g, NAME:b, NAME:a, and NAME the mean of r, g, b
            # (a grey painting's value). Paint on face corners is averaged
            # over each vertex's corners.
            rgba = np.empty(len(attribute.data) * 4, dtype=np.float32)
            attribute.data.foreach_get("color", rgba)
            rgba = rgba.reshape(-1, 4)
            if attribute.domain == "CORNER":
                if corner_vertex is None:
                    corner_vertex = np.empty(len(mesh.loops), dtype=np.int32)
                    mesh.loops.foreach_get("vertex_index", corner_vertex)
                sums = np.zeros((count, 4), dtype=np.float64)
                np.add.at(sums, corner_vertex, rgba)
                corners = np.bincount(corner_vertex, minlength=count).astype(np.float64)
                rgba = (sums / np.maximum(corners, 1.0)[:, None]).astype(np.float32)
            for k, channel in enumerate("rgba"):
                maps[f"{attribute.name}:{channel}"] = np.ascontiguousarray(rgba[:, k])
            maps[attribute.name] = rgba[:, :3].mean(axis=1).astype(np.float32)
    return maps


#: How the add-on's maps name a Blender image: ``image:NAME`` and
#: pelage's suffixes (``image:paint:r``, ``image:paint:g:clamp``).
IMAGE_PREFIX = "image:"
_IMAGE_FOLDER = []


def image_folder():
    """Where a session's Blender images are written for pelage to read (a
    temporary folder, kept while Blender runs: a groom's settings name
    the files)."""
    import tempfile

    if not _IMAGE_FOLDER:
        _IMAGE_FOLDER.append(tempfile.mkdtemp(prefix="pelage-images-"))
    return _IMAGE_FOLDER[0]


def png16(path, rows):
    """Writes ``rows`` (height × width × 4 floats, top row first) as a
    16-bit RGBA PNG, values clipped to 0–1: what pelage reads as a map
    with no loss a painter would see."""
    import struct
    import zlib

    height, width = rows.shape[:2]
    data = np.round(np.clip(rows, 0.0, 1.0) * 65535.0).astype(">u2").reshape(height, width * 4)
    raw = b"".join(b"\0" + row.tobytes() for row in data)

    def chunk(kind, payload):
        """One PNG chunk: length, kind, payload and CRC."""
        return (struct.pack(">I", len(payload)) + kind + payload
                + struct.pack(">I", zlib.crc32(kind + payload)))

    header = struct.pack(">IIBBBBB", width, height, 16, 6, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 6))
                + chunk(b"IEND", b""))


def blender_image_map(value, folder=None, relative=False, linear=False):
    """A map as pelage reads it: ``image:NAME[:SUFFIX...]`` names a Blender
    image (saved, packed, or painted and never saved), written from its
    pixels as a 16-bit PNG into ``folder`` (default ``image_folder()``)
    and named by its path (its file name when ``relative``) with the same
    suffixes; lists are resolved item by item; any other value as it
    is. With ``linear``, an sRGB image's colour is decoded to linear
    first (a colour, not data), into a file of its own."""
    if isinstance(value, list):
        return [blender_image_map(v, folder, relative, linear) for v in value]
    if not isinstance(value, str) or not value.startswith(IMAGE_PREFIX):
        return value
    import os

    import bpy
    import pelage

    parts = value[len(IMAGE_PREFIX):].split(":")
    for k in range(len(parts), 0, -1):
        name = ":".join(parts[:k])
        image = bpy.data.images.get(name)
        if image is not None:
            break
    else:
        raise pelage.PelageError(f"{value}: this .blend has no image {parts[0]!r}")
    width, height = image.size
    if width == 0 or height == 0:
        raise pelage.PelageError(f"{value}: the image {name!r} has no pixels (its file is missing?)")
    pixels = np.empty(width * height * 4, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    # Blender's first row of pixels is the image's bottom.
    rows = pixels.reshape(height, width, 4)[::-1]
    decode = linear and image.colorspace_settings.name == "sRGB"
    if decode:
        rgb = np.clip(rows[:, :, :3], 0.0, 1.0)
        rows = rows.copy()
        rows[:, :, :3] = np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)
    stem = "".join(c if c.isalnum() or c in "-_." else "_" for c in name)
    file_name = stem + ("-linear" if decode else "") + ".png"
    folder = folder or image_folder()
    png16(os.path.join(folder, file_name), rows)
    target = file_name if relative else os.path.join(folder, file_name)
    return ":".join([target] + parts[k:])


#: Blender's face sets: an integer attribute on faces.
FACE_SETS = ".sculpt_face_set"


def parting_attribute(obj):
    """The integer face attribute whose values are ``obj``'s parting
    regions: the one its panel names, else the sculpt face sets."""
    settings = getattr(obj, "pelage_fur", None)
    if settings is not None and settings.parting == "ATTRIBUTE" and settings.parting_attribute:
        return settings.parting_attribute
    return FACE_SETS


def face_sets_of(mesh, groups=FACE_SETS):
    """The mesh's face groups (the integer face attribute ``groups``: the
    sculpt face sets unless told) and material slots, one id a loop
    triangle, as ``Mesh.from_arrays`` takes them (``face_sets``,
    ``materials``): the regions of a parting (``regions={"faces":
    "groups" | "materials"}``). A mesh without the attribute has no
    groups; every mesh has material slots."""
    polygon = np.empty(len(mesh.loop_triangles), dtype=np.int32)
    mesh.loop_triangles.foreach_get("polygon_index", polygon)
    sets = {}
    materials = np.empty(len(mesh.polygons), dtype=np.int32)
    mesh.polygons.foreach_get("material_index", materials)
    sets["materials"] = materials[polygon]
    attribute = mesh.attributes.get(groups)
    if attribute is not None and attribute.domain == "FACE" and attribute.data_type == "INT":
        values = np.empty(len(mesh.polygons), dtype=np.int32)
        attribute.data.foreach_get("value", values)
        sets["face_sets"] = values[polygon]
    return sets


def follows_its_surface(obj):
    """Whether the Curves object ``obj`` has a geometry-nodes modifier
    with Deform Curves on Surface: its own curves are then in its
    surface's rest pose, and the evaluated ones posed."""
    return any(m.type == "NODES" and m.node_group is not None
               and any(n.bl_idname == "GeometryNodeDeformCurvesOnSurface" for n in m.node_group.nodes)
               for m in obj.modifiers)


def guides_from_curves_object(obj, depsgraph=None, rest=False):
    """The curves of the hair Curves object ``obj`` as a ``pelage.Curves``
    in pelage's Y-up world (``to_pelage_space``), to be bound to the
    surface as guides; any point count (pelage resamples them). Evaluated
    (its modifiers applied) with a ``depsgraph``; without, the curves as
    Blender's sculpt brushes leave them, read with no scene evaluation (a
    live update's). With ``rest``, guides that Deform Curves on Surface
    carries are read unevaluated, in the surface's rest pose, as the
    fur is grown there (``mesh_to_pelage``)."""
    import pelage

    if rest and follows_its_surface(obj):
        depsgraph = None
    data = obj.evaluated_get(depsgraph).data if depsgraph is not None else obj.data
    if len(data.curves) == 0:
        raise pelage.PelageError(f"{obj.name}: the guides object has no curves; add some with Blender's hair brushes")
    points = np.empty(len(data.points) * 3, dtype=np.float32)
    data.position_data.foreach_get("vector", points)
    offsets = np.empty(len(data.curves) + 1, dtype=np.int32)
    data.curve_offset_data.foreach_get("value", offsets)
    world = transform_points(to_pelage_space(obj), points.reshape(-1, 3))
    return pelage.Curves.from_arrays(world, offsets.astype(np.uint32))


def slider_ops(settings):
    """The operators the panel's Clump, Curl and Noise sliders stand for
    (0 turns one off), sized relative to the length."""
    import pelage

    ops = []
    if settings.clump > 0:
        clumps = max(1, settings.count // 100)
        ops.append(pelage.ops.clump(count=clumps, rate=settings.clump))
    if settings.curl > 0:
        ops.append(pelage.ops.curl(radius=settings.curl * settings.length * 0.05, turns=3))
    if settings.noise > 0:
        ops.append(pelage.ops.noise(amplitude=settings.noise * settings.length * 0.2,
                                    frequency=4.0 / max(settings.length, 1e-6)))
    return ops


def skin_color_image(obj):
    """The name of the Blender image the first material of ``obj`` takes
    its Base Color from (a Principled BSDF's Base Color linked from an
    Image Texture node), or None."""
    for slot in getattr(obj, "material_slots", ()):
        material = slot.material
        if material is None or material.node_tree is None:
            continue
        for node in material.node_tree.nodes:
            if node.type != "BSDF_PRINCIPLED":
                continue
            base = node.inputs.get("Base Color")
            if base is None or not base.is_linked:
                continue
            source = base.links[0].from_node
            if source.type == "TEX_IMAGE" and source.image is not None:
                return source.image.name
    return None


def groom_from_settings(mesh, settings, guides=None, size=1.0, skin=None, animation=None,
                        simulation=None, images=None, relative=False, skin_image=None):
    """A ``pelage.Groom`` on ``mesh`` from the panel's settings: the groom
    file when one is set (its ``[mesh]`` replaced by ``mesh``), else
    roots, the operator stack (or the Clump, Curl and Noise sliders when
    it is empty) and the look, shaped by
    ``guides`` (a ``pelage.Curves`` from ``guides_from_curves_object``,
    bound within a 200th of ``size``, the surface's largest dimension)
    or by guides grown on the surface. With ``skin`` (``{frame:
    vertices}``, ``mesh`` at the first frame) and ``animation`` (the
    ``[animation]`` table): animated, simulated with ``simulation``.
    Maps naming Blender images (``image:NAME:r``) are written into
    ``images`` (``blender_image_map``), by file name when ``relative``.
    With ``skin_image`` (``skin_color_image``'s) and Colour from Skin on,
    the hairs take that image's colour at their roots and no look: pelage
    fits each hair's melanin to its colour."""
    import pelage

    if settings.groom_file:
        import bpy

        path = bpy.path.abspath(settings.groom_file)
        if skin is None:
            return pelage.Groom.load(path, mesh=mesh)
        return pelage.Groom.load(path, mesh=mesh, skin=skin, frames=animation["frames"])
    if len(settings.ops):
        # The operator stack, when it has entries, replaces the sliders.
        from . import stack

        ops = [{kind: {key: blender_image_map(value, images, relative) for key, value in values.items()}
                for kind, values in op.items()} for op in stack.ops_of(settings.ops)]
    else:
        ops = slider_ops(settings)
    if guides is not None:
        guides = {"curves": guides, "points": max(settings.points, 4), "tolerance": size * 0.005}
    else:
        guides = {"generate": {"count": settings.guides, "length": settings.length,
                               "gravity": settings.gravity, "seed": settings.seed}}
    roots = {"count": settings.count, "seed": settings.seed}
    if settings.density_group.startswith(IMAGE_PREFIX):
        roots["density"] = blender_image_map(settings.density_group, images, relative)
    elif settings.density_group:
        roots["density"] = f"vertex:{settings.density_group}"
    parting = {"FACE_SETS": {"faces": "groups"}, "MATERIALS": {"faces": "materials"},
               "ATTRIBUTE": {"faces": "groups"}}
    interpolation = ({"method": "style-mesh"} if settings.interpolation == "STYLE_MESH"
                     else {"method": "shepard", "k": settings.interpolation_k})
    finish = {"points": settings.points, "outside_skin": settings.outside_skin,
              "width": {"root": settings.width, "tip": settings.width * 0.1}}
    look = {"melanin": settings.melanin, "melanin_redness": settings.melanin_redness,
            "roughness": settings.roughness, "radial_roughness": settings.radial_roughness,
            "jitter": settings.look_jitter, "seed": settings.seed}
    if skin_image is not None and settings.skin_color:
        rgb = blender_image_map([f"{IMAGE_PREFIX}{skin_image}:{c}" for c in "rgb"], images, relative,
                                linear=True)
        finish["color"] = {"root": rgb, "tip": rgb}
        look = None
    return pelage.Groom(
        mesh=mesh,
        interpolation=interpolation,
        base_dir=images if relative else None,
        skin=skin,
        animation=animation,
        simulation=simulation,
        guides=guides,
        regions=parting.get(settings.parting),
        roots=roots,
        ops=ops,
        finish=finish,
        look=look,
    )


def curves_to_blender(name, curves, surface=None, uv_map=None, matrix=None):
    """A new hair Curves datablock holding ``curves`` (a ``pelage.Curves``):
    positions (through the 4×4 ``matrix`` when given), ``radius`` (half
    pelage's widths), ``color`` when the groom has colours, ``hair_id`` per
    curve (pelage's stable id, low 31 bits), ``surface_uv_coordinate``
    bound to ``surface``'s ``uv_map``, and with a look the per-hair shader
    values with the material that reads them (``hair_material``)."""
    import bpy

    data = bpy.data.hair_curves.new(name)
    sizes = np.diff(curves.offsets.astype(np.int64))
    data.add_curves(sizes.tolist())
    points = curves.points if matrix is None else transform_points(matrix, curves.points)
    data.position_data.foreach_set("vector", points.ravel())
    radius = data.attributes.get("radius") or data.attributes.new("radius", "FLOAT", "POINT")
    radius.data.foreach_set("value", curves.widths * np.float32(0.5))
    if curves.colors is not None:
        color = data.attributes.new(COLOR, "FLOAT_COLOR", "POINT")
        rgba = np.ones((curves.point_count, 4), dtype=np.float32)
        rgba[:, :3] = curves.colors
        color.data.foreach_set("color", rgba.ravel())
    if curves.ids is not None:
        ids = data.attributes.new(HAIR_ID, "INT", "CURVE")
        ids.data.foreach_set("value", (curves.ids & 0x7FFFFFFF).astype(np.int32))
    if curves.root_uvs is not None:
        uv = data.attributes.new("surface_uv_coordinate", "FLOAT2", "CURVE")
        uv.data.foreach_set("vector", curves.root_uvs.ravel())
    # Plain arrays (the benchmark's stand-in for Curves) carry no look.
    shading = getattr(curves, "shading", None)
    if shading is not None:
        for name in SHADING_FLOATS:
            data.attributes.new(name, "FLOAT", "CURVE").data.foreach_set("value", shading[name])
        rgba = np.ones((curves.curve_count, 4), dtype=np.float32)
        rgba[:, :3] = shading[TINT]
        data.attributes.new(TINT, "FLOAT_COLOR", "CURVE").data.foreach_set("color", rgba.ravel())
        data.materials.append(hair_material())
    if surface is not None:
        data.surface = surface
        if uv_map:
            data.surface_uv_map = uv_map
    return data


def hair_material():
    """The material ``pelage hair`` (made once a file): Blender's Principled
    Hair BSDF, Chiang model with the melanin parametrization, its melanin,
    redness, tint, roughnesses and random number read per hair from
    pelage's attributes. It is the MaterialX network pelage writes to USD,
    in Cycles' own node, so a groom looks alike in both; it also shades
    curves imported from a pelage USD file, whose primvars arrive as these
    attributes."""
    import bpy

    material = bpy.data.materials.get(HAIR_MATERIAL)
    if material is not None:
        return material
    material = bpy.data.materials.new(HAIR_MATERIAL)
    material.use_nodes = True
    nodes, links = material.node_tree.nodes, material.node_tree.links
    nodes.clear()
    output = nodes.new("ShaderNodeOutputMaterial")
    hair = nodes.new("ShaderNodeBsdfHairPrincipled")
    hair.model = "CHIANG"
    hair.parametrization = "MELANIN"
    hair.location = (-300, 0)
    links.new(hair.outputs["BSDF"], output.inputs["Surface"])
    inputs = [("Melanin", "hair_melanin"), ("Melanin Redness", "hair_melanin_redness"),
              ("Tint", TINT), ("Roughness", "hair_roughness"),
              ("Radial Roughness", "hair_radial_roughness"), ("Random", "hair_random")]
    for k, (socket, name) in enumerate(inputs):
        attribute = nodes.new("ShaderNodeAttribute")
        attribute.attribute_type = "GEOMETRY"
        attribute.attribute_name = name
        attribute.location = (-600, 200 - 120 * k)
        value = attribute.outputs["Color" if name == TINT else "Fac"]
        links.new(value, hair.inputs[socket])
    return material


#: The node group of the fur's Deform Curves on Surface modifier.
DEFORM_GROUP = "pelage: deform curves on surface"


def deform_on_surface_modifier(obj):
    """Adds a geometry-nodes modifier with Blender's Deform Curves on
    Surface node to the curves object ``obj``: the fur follows its surface
    when the surface deforms (armature, shape keys)."""
    import bpy

    tree = bpy.data.node_groups.get(DEFORM_GROUP)
    if tree is None:
        tree = bpy.data.node_groups.new(DEFORM_GROUP, "GeometryNodeTree")
        tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
        tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
        group_in = tree.nodes.new("NodeGroupInput")
        group_out = tree.nodes.new("NodeGroupOutput")
        deform = tree.nodes.new("GeometryNodeDeformCurvesOnSurface")
        tree.links.new(group_in.outputs["Geometry"], deform.inputs["Curves"])
        tree.links.new(deform.outputs["Curves"], group_out.inputs["Geometry"])
    modifier = obj.modifiers.new("Deform Curves on Surface", "NODES")
    modifier.node_group = tree
    return modifier


def surface_deforms(surface):
    """Whether anything moves the vertices of ``surface`` under its fur:
    shape keys or a modifier (an armature's, a lattice's, a
    displacement…). Without them the mesh Blender shows is its rest pose,
    Deform Curves on Surface would move nothing, and the object's own
    motion carries the fur by the parenting alone."""
    return surface.data.shape_keys is not None or len(surface.modifiers) > 0


def deform_modifier_of(obj):
    """The fur object's Deform Curves on Surface modifier, or None."""
    return next((m for m in obj.modifiers if m.type == "NODES" and m.node_group is not None
                 and m.node_group.name == DEFORM_GROUP), None)


def follow_surface(obj, surface):
    """Gives the fur ``obj`` Deform Curves on Surface when ``surface``
    deforms and has a UV map, and takes it away when it no longer does:
    the node recomputes every point on every update of the fur (180 ms at
    1.2 M points, most of a live comb's time), for nothing on a mesh that
    nothing deforms. A user's own modifiers stay."""
    modifier = deform_modifier_of(obj)
    needed = surface.data.uv_layers.active is not None and surface_deforms(surface)
    if needed and modifier is None:
        # The node compares the deformed surface with its rest positions.
        use_rest_positions(surface)
        deform_on_surface_modifier(obj)
    elif not needed and modifier is not None:
        obj.modifiers.remove(modifier)


def guide_warnings(report):
    """The guides a groom leaves out, with why, from its report (the
    library's: ``Groom.report()`` or ``Groom.write()["report"]``)."""
    guides = report["guides"]
    notes = [f"guide {d['guide']} left out: {d['why']}" for d in guides["dropped"]]
    notes += [note["why"] for note in guides["unused_by_style_mesh"]]
    return notes


def groom_for(surface, settings, mesh, depsgraph, images=None, relative=False, rest=False):
    """The groom the panel of ``surface`` describes on its pelage ``mesh``,
    with the guides object's curves as guides when one is set (at rest
    with ``rest``, as ``mesh`` is then; Blender images its maps name
    written into ``images``, as ``groom_from_settings`` does)."""
    guides = None
    if settings.guides_object is not None and not settings.groom_file:
        guides = guides_from_curves_object(settings.guides_object, depsgraph, rest=rest)
    return groom_from_settings(mesh, settings, guides, max(surface.dimensions) or 1.0,
                               images=images, relative=relative, skin_image=skin_color_image(surface))


def evaluated_positions(obj, depsgraph):
    """The vertices of ``obj`` as ``depsgraph`` evaluates it (modifiers,
    shape keys, armature), in pelage's Y-up world, float32 (n, 3)."""
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        positions = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
        mesh.vertices.foreach_get("co", positions)
        return transform_points(to_pelage_space(obj), positions.reshape(-1, 3))
    finally:
        evaluated.to_mesh_clear()


def grows_at_rest(surface):
    """Whether fur on ``surface`` is grown on its rest pose: when it has a
    UV map, so that Deform Curves on Surface carries the fur to the pose
    on screen (without one the fur stays where it was grown, and is grown
    on the mesh as it is). When it is, Blender is asked to keep the rest
    pose (``use_rest_positions``) before the mesh is next evaluated."""
    rest = surface.data.uv_layers.active is not None
    if rest:
        use_rest_positions(surface)
    return rest


def animated_groom_for(context, surface, settings, progress=None, frames=None, rest_frame=None,
                       mode=None):
    """The panel's groom on ``surface`` as Blender evaluates it at
    ``frames`` (``(first, last)``, default the scene's frame range): the
    surface's rest pose (before armature and shape keys, as Deform Curves
    on Surface carries the viewport's fur from) where the object is at
    ``rest_frame`` (default the first) is where roots are sampled and
    guides bound, its vertices at every frame the skin
    (armatures, shape keys, modifiers, object motion: whatever Blender
    shows). ``mode`` ("deform" or "simulate", default the panel's Motion)
    deforms the fur with the skin or simulates the guides on it (gravity:
    the scene's). The scene is left at the frame it was on.
    ``progress(done, total)`` as frames are read."""
    scene = context.scene
    first, last = frames if frames is not None else (scene.frame_start, scene.frame_end)
    if last < first:
        raise ValueError(f"the scene's frame range {first}-{last} is empty")
    rest_frame = first if rest_frame is None else rest_frame
    wanted = sorted(set(range(first, last + 1)) | {rest_frame})
    current = scene.frame_current
    skin = {}
    use_rest_positions(surface)
    try:
        scene.frame_set(rest_frame)
        depsgraph = context.evaluated_depsgraph_get()
        mesh, _ = mesh_to_pelage(surface, depsgraph, rest=True)
        guides = None
        if settings.guides_object is not None and not settings.groom_file:
            guides = guides_from_curves_object(settings.guides_object, depsgraph, rest=True)
        for k, frame in enumerate(wanted):
            scene.frame_set(frame)
            skin[frame] = evaluated_positions(surface, context.evaluated_depsgraph_get())
            if len(skin[frame]) != mesh.vertex_count:
                import pelage

                raise pelage.PelageError(
                    f"{surface.name}: {len(skin[frame])} vertices at frame {frame} and "
                    f"{mesh.vertex_count} at frame {rest_frame}: animated fur needs a mesh whose "
                    "topology does not change (no remesh, decimate or booleans that animate)")
            if progress is not None:
                progress(k + 1, len(wanted))
    finally:
        scene.frame_set(current)
    mode = mode or settings.animation_mode.lower()
    animation = {"frames": f"{first}-{last}" if last > first else f"{first}", "mode": mode,
                 "rest_frame": rest_frame, "fps": scene.render.fps / scene.render.fps_base}
    simulation = None
    if mode == "simulate":
        gravity = Z_UP_TO_Y_UP @ np.array(scene.gravity, dtype=np.float64)
        simulation = {
            "gravity": [float(g) for g in gravity] if scene.use_gravity else [0.0, 0.0, 0.0],
            "follow": settings.sim_follow,
            "bend": settings.sim_bend,
            "damping": settings.sim_damping,
            "collide": settings.sim_collide,
            "preroll": settings.sim_preroll,
        }
    return groom_from_settings(mesh, settings, guides, max(surface.dimensions) or 1.0,
                               skin=skin, animation=animation, simulation=simulation,
                               skin_image=skin_color_image(surface))


def export_groom_for(context, surface, settings):
    """The groom an export writes: the fur as the viewport shows it (or
    would, grown now). Grown on the rest pose where the object was at the
    grow's frame, and carried by Deform Curves on Surface to the frame on
    screen: on another frame or a posed surface it is that groom carried
    to this one (one time sample); at the grow's frame on a surface at
    rest, or before any grow, grown on the mesh as it is."""
    fur = fur_object_of(surface)
    current = context.scene.frame_current
    grown_at = fur.get("pelage_frame", current) if fur is not None else current
    if grown_at == current:
        rest = grows_at_rest(surface)
        depsgraph = context.evaluated_depsgraph_get()
        mesh, _ = mesh_to_pelage(surface, depsgraph, rest=rest)
        if not rest or np.array_equal(mesh.positions, evaluated_positions(surface, depsgraph)):
            return groom_for(surface, settings, mesh, depsgraph, rest=rest)
    return animated_groom_for(context, surface, settings, frames=(current, current),
                              rest_frame=int(grown_at), mode="deform")


def save_groom_file(context, surface, settings, path):
    """Writes the panel of ``surface`` as the groom file ``path``: the
    library's own text for the groom the panel grows (``Groom.settings``:
    every operator of the stack with its settings and masks, roots,
    finish, look; no ``[mesh]``, which the object stands for), with a
    guides object's curves written beside it (``NAME.guides.usdc``, in
    pelage's Y-up world) and named in ``[guides] file``, and the Blender
    images its maps name beside it as 16-bit PNGs. Each file is
    written whole or not at all. Returns the paths written."""
    import os

    import pelage

    rest = grows_at_rest(surface)
    depsgraph = context.evaluated_depsgraph_get()
    mesh, _ = mesh_to_pelage(surface, depsgraph, rest=rest)
    # Blender images the maps name go beside the file, by name; a folder
    # typed in the file browser that is not there yet is made.
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    groom = groom_for(surface, settings, mesh, depsgraph, images=folder, relative=True, rest=rest)
    text = groom.settings
    written = [path]
    if settings.guides_object is not None:
        guides = guides_from_curves_object(settings.guides_object, depsgraph, rest=rest)
        guides_path = os.path.splitext(path)[0] + ".guides.usdc"
        pelage.write_curves(guides, guides_path, basis="linear")
        written.append(guides_path)
        if "[guides]\n" not in text:
            raise pelage.PelageError("the groom's settings have no [guides] table to name the guides file in")
        text = text.replace("[guides]\n", f'[guides]\nfile = "{os.path.basename(guides_path)}"\n', 1)
    temporary = f"{path}.tmp-{os.getpid()}"
    try:
        with open(temporary, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(temporary, path)
    finally:
        if os.path.exists(temporary):
            os.remove(temporary)
    return written


def fur_object_of(surface):
    """The fur a grow made on ``surface`` before (a Curves object parented
    to it that carries pelage's settings), or None."""
    return next((o for o in surface.children if o.type == "CURVES" and "pelage_settings" in o), None)


#: What Length and Width start at on an object, fractions of its largest
#: dimension (``size_defaults``), until the user or a preset sets them.
SIZED_DEFAULTS = dict(length=0.04, width=0.0006)


def size_defaults(surface):
    """Length and Width sized to ``surface`` (a 15 cm bunny gets 6 mm fur,
    not 5 cm) the first time it grows, unless they were set."""
    settings = surface.pelage_fur
    if settings.sized:
        return
    size = max(surface.dimensions) or 1.0
    settings.length = SIZED_DEFAULTS["length"] * size
    settings.width = SIZED_DEFAULTS["width"] * size
    settings.sized = True


class Cancelled(Exception):
    """A grow the user cancelled (Esc): nothing was changed."""


def is_live(settings):
    """Whether the panel ``settings`` grow a live groom: Live on, a guides
    object to sculpt, the panel's own settings (not a groom file)."""
    return settings.live and settings.guides_object is not None and not settings.groom_file


class PreparedGrow:
    """What a grow reads from Blender, on the main thread, before pelage
    grows (``grow_curves``, which touches no Blender data and may run on
    another thread) and the result goes back into Blender
    (``finish_grow``)."""

    def __init__(self, context, surface, settings):
        """Reads everything the grow needs from Blender, on the main thread:
        the evaluated mesh, its maps, the guides and the groom."""
        import time

        self.start = time.perf_counter()
        size_defaults(surface)
        # On the rest pose whatever frame is on screen: Deform Curves on
        # Surface carries the fur from there to the pose.
        rest = grows_at_rest(surface)
        depsgraph = context.evaluated_depsgraph_get()
        mesh, self.uv_map = mesh_to_pelage(surface, depsgraph, rest=rest)
        self.groom = groom_for(surface, settings, mesh, depsgraph, rest=rest)
        self.live = is_live(settings)
        self.fraction = settings.display_fraction
        self.frame = context.scene.frame_current


def grow_curves(prepared, progress=None):
    """Grows the prepared groom: ``(curves, live session or None)``. A live
    groom is a pelage session at the display fraction (sculpting the
    guides regrows the hairs near the stroke); otherwise the whole groom,
    part by part, calling ``progress(done, total)`` after each, which
    may raise ``Cancelled`` to stop it. Touches no Blender data."""
    if prepared.live:
        import pelage

        session = pelage.GroomSession(prepared.groom, fraction=prepared.fraction)
        return session.curves(), session
    return prepared.groom.grow(progress=progress), None


def replace_data(obj, data):
    """Gives the fur object ``obj`` its regrown curves ``data`` in place:
    it keeps its name, its modifiers and whatever material the user gave
    it; the old curves go when nothing else uses them."""
    import bpy

    old = obj.data
    # Every slot is kept, empty ones too: a material the user linked to the
    # object (not the data) lives in the object's slot of the same index.
    if len(old.materials):
        data.materials.clear()
        for material in old.materials:
            data.materials.append(material)
    obj.data = data
    name = old.name
    if old.users == 0:
        bpy.data.hair_curves.remove(old)
        data.name = name


def finish_grow(surface, settings, prepared, grown, session):
    """Puts ``grown`` into the surface's fur object (the one an earlier
    grow made, regrown in place, or a new one parented to it). Returns
    ``(curves_object, warnings)``: the guides the groom left out, with
    why, and a mesh without a UV map."""
    import time

    import bpy

    LIVE.pop(surface.name, None)
    # This grow is the regrow a live update scheduled before it would do.
    PENDING.pop(surface.name, None)
    uv_map, groom = prepared.uv_map, prepared.groom
    # Back from pelage's Y-up world into the surface's local space, where
    # Blender keeps the points of curves parented to it.
    back = np.linalg.inv(to_pelage_space(surface))
    data = curves_to_blender(f"{surface.name} fur", grown, surface, uv_map, back)
    obj = fur_object_of(surface)
    if obj is None:
        obj = bpy.data.objects.new(f"{surface.name} fur", data)
        for collection in surface.users_collection:
            collection.objects.link(obj)
        obj.parent = surface
        # Curves points are in the surface's space: the object sits on it.
        obj.matrix_parent_inverse.identity()
    else:
        replace_data(obj, data)
    follow_surface(obj, surface)
    obj["pelage_settings"] = groom.settings
    # Where the object was when grown (the rest pose is moved by the
    # object's own transform): exports at other frames start from there.
    obj["pelage_frame"] = prepared.frame
    if session is not None:
        LIVE[surface.name] = LiveGroom(session, obj.name, max(surface.dimensions) * 0.005 or 1e-3)
    report = groom.report()
    settings.last_grow = "\n".join(grow_summary(report, grown, time.perf_counter() - prepared.start))
    warnings = guide_warnings(report)
    if uv_map is None:
        warnings.append(f"{surface.name} has no UV map: the fur is grown but will not follow the mesh "
                        "when it deforms (Deform Curves on Surface needs UVs); add a UV map and grow again")
    return obj, warnings


def grow_on_object(context, surface, settings, progress=None):
    """Grows fur on the mesh object ``surface`` into a Curves object
    parented to it: the one an earlier grow made, regrown in place, or a
    new one (``PreparedGrow``, ``grow_curves``, ``finish_grow`` in turn,
    on this thread). Returns ``(curves_object, pelage_curves, warnings)``."""
    prepared = PreparedGrow(context, surface, settings)
    grown, session = grow_curves(prepared, progress)
    obj, warnings = finish_grow(surface, settings, prepared, grown, session)
    return obj, grown, warnings


def grow_summary(report, grown, seconds):
    """The panel's lines about a grow: hairs, points and time; with
    regions, each one's hairs and guides (a region without guides borrows
    every guide); the guides left out."""
    lines = [f"{grown.curve_count:,} hairs, {grown.point_count:,} points in {seconds:.2f} s"]
    regions = report.get("regions") or []
    if regions and grown.regions is not None:
        ids, counts = np.unique(grown.regions, return_counts=True)
        hairs = dict(zip(ids.tolist(), counts.tolist()))
        for region in regions:
            guides = region["guides"] or "no guides: borrows all"
            lines.append(f"region {region['name']}: {hairs.get(region['region'], 0):,} hairs, guides {guides}")
    dropped = len(report["guides"]["dropped"]) + len(report["guides"]["unused_by_style_mesh"])
    if dropped:
        lines.append(f"{dropped} guides left out (see the warnings)")
    return lines


class LiveGroom:
    """A surface's live groom: its pelage session, the fur object it
    fills, and the tolerance its guides are bound with."""

    def __init__(self, session, fur_name, tolerance):
        """A live groom of ``session`` filling the object named ``fur_name``."""
        self.session = session
        self.fur_name = fur_name
        self.tolerance = tolerance
        # Set while the depsgraph has yet to see the fur this groom just
        # filled: a new or replaced datablock makes the next update touch
        # every ID (the mesh and the guides among them), which is no edit
        # of the user's and must not regrow the groom again.
        self.settling = True


#: Live grooms by surface object name.
LIVE = {}
#: Surfaces whose live update is scheduled (a stroke's many depsgraph
#: updates make one regrow), with whether it is a whole regrow (the mesh,
#: its paint or a setting changed) rather than the guides' own.
PENDING = {}


def live_update(surface):
    """Regrows the live fur of ``surface`` after its guides object changed:
    the guides whose points moved regrow their hairs only (pelage's
    incremental regrowth); the fur object's points are replaced in place
    (a new datablock when the hair count changed). Returns pelage's
    ``{"regrown", "hairs"}``, or None when nothing changed or the surface
    has no live groom."""
    import bpy

    live = LIVE.get(surface.name)
    obj = bpy.data.objects.get(live.fur_name) if live else None
    guides_object = surface.pelage_fur.guides_object
    if obj is None or guides_object is None:
        return None
    guides = guides_from_curves_object(guides_object)
    done = live.session.set_guides(guides, tolerance=live.tolerance)
    if done is None:
        return None
    back = np.linalg.inv(to_pelage_space(surface))
    data = obj.data
    if done["hairs"] == len(data.curves):
        # The same hairs: their points alone, moved in place.
        points = live.session.points(back)
        if len(points) == len(data.points):
            data.position_data.foreach_set("vector", points.ravel())
            data.update_tag()
            return done
    # Hairs added or removed: a new datablock, in place of the old one as
    # a grow puts it (the user's material and the object's slots kept).
    replace_data(obj, curves_to_blender(data.name, live.session.curves(), surface, data.surface_uv_map or None, back))
    live.settling = True
    return done


def live_regrow(surface):
    """Regrows the live fur of ``surface`` whole, after its mesh (edit
    mode, sculpting), its paint (vertex groups, colour attributes) or a
    panel setting changed: the evaluated mesh and the panel's groom, at
    the display fraction, into the same fur object. Returns ``{"hairs"}``,
    or None when the surface has no live groom."""
    import bpy

    live = LIVE.get(surface.name)
    # Live ticked after a Grow: the fur that grow made becomes live.
    obj = bpy.data.objects.get(live.fur_name) if live else fur_object_of(surface)
    if obj is None or not is_live(surface.pelage_fur):
        return None
    prepared = PreparedGrow(bpy.context, surface, surface.pelage_fur)
    grown, session = grow_curves(prepared)
    back = np.linalg.inv(to_pelage_space(surface))
    replace_data(obj, curves_to_blender(obj.data.name, grown, surface, prepared.uv_map, back))
    if live is None:
        LIVE[surface.name] = LiveGroom(session, obj.name, max(surface.dimensions) * 0.005 or 1e-3)
    else:
        live.session, live.settling = session, True
    return {"hairs": grown.curve_count}


def schedule_live_update(name, whole=False):
    """Runs ``live_update`` (or ``live_regrow`` when ``whole``) on the
    surface ``name`` once, shortly: the depsgraph reports a sculpt stroke
    many times."""
    import bpy

    if name in PENDING:
        PENDING[name] = PENDING[name] or whole
        return
    PENDING[name] = whole

    def run():
        """The timer's callback: the scheduled regrow, its errors kept from
        Blender's timer."""
        import pelage

        whole = PENDING.pop(name, False)
        surface = bpy.data.objects.get(name)
        if surface is None:
            return None
        try:
            done = live_regrow(surface) if whole else live_update(surface)
        except pelage.PelageError as error:
            # A timer has no operator to report through: the panel says it.
            surface.pelage_fur.last_grow = f"live: {error}"
            return None
        if done is not None and whole:
            surface.pelage_fur.last_grow = f"live: regrown, {done['hairs']:,} hairs shown"
        elif done is not None:
            surface.pelage_fur.last_grow = f"live: {done['regrown']:,} of {done['hairs']:,} hairs regrown"
        return None

    bpy.app.timers.register(run, first_interval=0.05)


def on_live_toggled(settings, _context):
    """Live ticked: a surface with pelage fur grown but no live groom gets
    one (a whole regrow, scheduled), so sculpting the guides regrows the
    fur without another Grow. Unticked: the live groom is let go."""
    surface = settings.id_data
    if surface is None:
        return
    if not settings.live:
        LIVE.pop(surface.name, None)
        PENDING.pop(surface.name, None)
        return
    if surface.name not in LIVE and is_live(settings) and fur_object_of(surface) is not None:
        schedule_live_update(surface.name, whole=True)


def on_setting_change(settings, _context):
    """A panel setting (or one of the operator stack's, ``settings`` being
    the property group changed) changed: a live groom regrows whole."""
    surface = settings.id_data
    if surface is None or surface.name not in LIVE or not surface.pelage_fur.live:
        return
    schedule_live_update(surface.name, whole=True)


def on_depsgraph_update(scene, depsgraph):
    """Schedules the live update of every live surface whose guides object
    (or its curves) the update touched, and a whole regrow of every one
    whose mesh it touched."""
    import bpy

    touched = {update.id.original for update in depsgraph.updates}
    # A surface rigged, shape-keyed or given a modifier after its fur
    # was grown: the fur follows it from now on.
    for surface in touched:
        if isinstance(surface, bpy.types.Object) and surface.type == "MESH":
            fur = fur_object_of(surface)
            if fur is not None:
                follow_surface(fur, surface)
    for name in list(LIVE):
        surface = bpy.data.objects.get(name)
        if surface is None:
            LIVE.pop(name, None)
            continue
        settings = surface.pelage_fur
        guides = settings.guides_object
        if not settings.live or guides is None:
            continue
        live = LIVE[name]
        if live.settling:
            live.settling = False
            continue
        # The mesh datablock itself (edit mode, sculpting, weight and
        # vertex paint), not the object evaluated again (an armature
        # playing moves the fur through Deform Curves on Surface).
        if surface.data in touched:
            schedule_live_update(name, whole=True)
        elif guides in touched or guides.data in touched:
            schedule_live_update(name)
