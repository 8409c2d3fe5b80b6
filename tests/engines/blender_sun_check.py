# Blender's own check of a latlong as a World texture (tests/e2e/engine_blender_test.cc):
#   blender -b --factory-startup --python blender_sun_check.py -- SCENE.glb LATLONG.exr OUT_DIR [TURN_DEG]
# Imports the scene with Blender's glTF importer, sets LATLONG as the World's
# Environment Texture with the default mapping, hides the scene's dome (its
# UVs are skybake's own) and renders, with Cycles (no denoiser), a 3-degree
# camera along the imported sun light's direction and turned 90, 180 and 270
# degrees about Blender's vertical (+Z). With TURN_DEG the texture's lookup
# is turned about +Z by that angle first, as docs/engines.md tells a user to
# turn an OpenEXR latlong: a Texture Coordinate node's Generated output (the
# view direction, for a World) through a Mapping node (Point, Rotation Z =
# TURN_DEG) into the Environment Texture's Vector. Prints one line:
#   RESULT {"sun": [x, y, z], "radiance": [r0, r90, r180, r270]}
# with the mean of each render (linear, the EXR's values).
import json
import math
import os
import sys

import numpy

numpy.bool = bool  # Debian 12's Blender 3.4 glTF importer uses np.bool, gone from numpy 1.24

import bpy
import mathutils

args = sys.argv[sys.argv.index("--") + 1:]
scene_path, latlong_path, out_dir = args[:3]
turn_deg = float(args[3]) if len(args) > 3 else None
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=scene_path)
suns = [o for o in bpy.data.objects if o.type == "LIGHT" and o.data.type == "SUN"]
if len(suns) != 1:
    sys.exit(f"expected one sun light in {scene_path}, found {len(suns)}")
# A Blender light shines along its local -Z: the Sun is along +Z.
to_sun = (suns[0].matrix_world.to_3x3() @ mathutils.Vector((0.0, 0.0, 1.0))).normalized()
for o in bpy.data.objects:
    if o.type == "MESH":
        o.hide_render = True

scene = bpy.context.scene
world = bpy.data.worlds.new("sky")
scene.world = world
world.use_nodes = True
nodes = world.node_tree.nodes
texture = nodes.new("ShaderNodeTexEnvironment")
texture.image = bpy.data.images.load(latlong_path)
texture.interpolation = "Closest"
world.node_tree.links.new(texture.outputs["Color"], nodes["Background"].inputs["Color"])
if turn_deg is not None:
    coordinates = nodes.new("ShaderNodeTexCoord")
    mapping = nodes.new("ShaderNodeMapping")
    mapping.vector_type = "POINT"
    mapping.inputs["Rotation"].default_value = (0.0, 0.0, math.radians(turn_deg))
    world.node_tree.links.new(coordinates.outputs["Generated"], mapping.inputs["Vector"])
    world.node_tree.links.new(mapping.outputs["Vector"], texture.inputs["Vector"])

camera_data = bpy.data.cameras.new("probe")
camera_data.angle = math.radians(3.0)
camera = bpy.data.objects.new("probe", camera_data)
scene.collection.objects.link(camera)
scene.camera = camera
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = 4
scene.cycles.use_denoising = False
scene.render.resolution_x = 16
scene.render.resolution_y = 16
scene.render.resolution_percentage = 100
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
scene.view_settings.view_transform = "Standard"

radiance = []
for turn in (0, 90, 180, 270):
    direction = mathutils.Matrix.Rotation(math.radians(turn), 3, "Z") @ to_sun
    camera.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
    scene.render.filepath = os.path.join(out_dir, f"probe_{turn}.exr")
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(scene.render.filepath)
    pixels = numpy.array(image.pixels[:]).reshape(-1, 4)
    radiance.append(float(pixels[:, :3].mean()))
print("RESULT " + json.dumps({"sun": list(to_sun), "radiance": radiance}))
