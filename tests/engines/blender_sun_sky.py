# The bake's sky and Sun together in Blender, in units (tests/e2e/engine_blender_test.cc,
# SkyAndSunShowOneExposure):
#   blender -b --factory-startup --python blender_sun_sky.py -- \
#       SCENE.glb LATLONG.exr OUT_DIR ALBEDO FOV_DEG SIZE LIGHTING_MODE BACKGROUND_STRENGTH SAMPLES SKY_VIEWS
# Imports the scene with Blender's glTF importer (its "Lighting Mode",
# convert_lighting_mode = SPEC | COMPAT | RAW: SPEC, the default, makes the sun's
# Strength lux / 683 W/m^2; COMPAT keeps the number), hides its meshes (the dome
# is textured with the LDR preview PNG), sets LATLONG as the World's Environment
# Texture (Background Strength BACKGROUND_STRENGTH: 1/683 puts the sky, in cd/m^2
# in the file, in the same W-based units as the SPEC sun), puts an up-facing grey
# card (Diffuse BSDF, ALBEDO, roughness 0: Lambertian) at the origin and renders
# with Cycles (CPU, SAMPLES per pixel, no denoiser, direct light only: nothing
# else in the scene to bounce from), at one exposure (view transform Standard,
# exposure 0, look None, written as a 32-bit float EXR: linear), square views
# of FOV_DEG and SIZE pixels from 2 m up: the sky along each of SKY_VIEWS
# ("x,y,z;...", skybake's world, +Y up: Blender's (x, -z, y) after the glTF
# importer's axes), and straight down at the card; then the card under the sun
# alone and under the sky alone. Prints
#   RESULT {"sky": [r, g, b] (the views' mean), "sky_views": [[r, g, b], ...],
#           "card": [...], "card_sun_only": [...],
#           "card_sky_only": [...], "sun": {"strength": S, "color": [...],
#           "angle": rad, "to_sun": [x, y, z]}}
# with each view's mean linear RGB, in the render's units.
import json
import math
import os
import sys

import numpy

numpy.bool = bool  # Debian 12's Blender 3.4 glTF importer uses np.bool, gone from numpy 1.24

import bpy
import mathutils

(scene_path, latlong_path, out_dir, albedo, fov_deg, size, lighting_mode, background_strength,
 samples, sky_views) = sys.argv[sys.argv.index("--") + 1:][:10]
albedo, fov_deg, background_strength = float(albedo), float(fov_deg), float(background_strength)
size, samples = int(size), int(samples)

bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=scene_path, convert_lighting_mode=lighting_mode)
suns = [o for o in bpy.data.objects if o.type == "LIGHT" and o.data.type == "SUN"]
if len(suns) != 1:
    sys.exit(f"expected one sun light in {scene_path}, found {len(suns)}")
sun = suns[0]
# A Blender light shines along its local -Z: the Sun is along +Z.
to_sun = (sun.matrix_world.to_3x3() @ mathutils.Vector((0.0, 0.0, 1.0))).normalized()
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
world.node_tree.links.new(texture.outputs["Color"], nodes["Background"].inputs["Color"])
nodes["Background"].inputs["Strength"].default_value = background_strength

bpy.ops.mesh.primitive_plane_add(size=4.0, location=(0.0, 0.0, 0.0))  # faces +Z, Blender's up
card = bpy.context.active_object
material = bpy.data.materials.new("grey card")
material.use_nodes = True
material.node_tree.nodes.clear()
diffuse = material.node_tree.nodes.new("ShaderNodeBsdfDiffuse")
diffuse.inputs["Color"].default_value = (albedo, albedo, albedo, 1.0)
diffuse.inputs["Roughness"].default_value = 0.0
output = material.node_tree.nodes.new("ShaderNodeOutputMaterial")
material.node_tree.links.new(diffuse.outputs["BSDF"], output.inputs["Surface"])
card.data.materials.append(material)

camera_data = bpy.data.cameras.new("probe")
camera_data.angle = math.radians(fov_deg)
camera_data.clip_start = 0.1
camera = bpy.data.objects.new("probe", camera_data)
scene.collection.objects.link(camera)
scene.camera = camera
camera.location = (0.0, 0.0, 2.0)
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = samples
scene.cycles.use_denoising = False
scene.cycles.max_bounces = 0
scene.render.resolution_x = size
scene.render.resolution_y = size
scene.render.resolution_percentage = 100
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
scene.view_settings.view_transform = "Standard"
scene.view_settings.look = "None"
scene.view_settings.exposure = 0.0
scene.view_settings.gamma = 1.0


def look(name, direction, up):
    """Mean linear RGB of the view from the camera along `direction`."""
    camera.rotation_euler = mathutils.Vector(direction).to_track_quat("-Z", up).to_euler()
    scene.render.filepath = os.path.join(out_dir, f"sun_sky_{name}.exr")
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(scene.render.filepath)
    pixels = numpy.array(image.pixels[:]).reshape(-1, 4)
    return [float(v) for v in pixels[:, :3].mean(axis=0)]


result = {"sun": {"strength": sun.data.energy, "color": list(sun.data.color), "angle": sun.data.angle,
                  "to_sun": list(to_sun)}}
views = [[float(v) for v in t.split(",")] for t in sky_views.split(";")]
result["sky_views"] = [look(f"sky{i}", (x, -z, y), "Y") for i, (x, y, z) in enumerate(views)]
result["sky"] = [sum(m[c] for m in result["sky_views"]) / len(views) for c in range(3)]
result["card"] = look("card", (0.0, 0.0, -1.0), "Y")
nodes["Background"].inputs["Strength"].default_value = 0.0
result["card_sun_only"] = look("card_sun_only", (0.0, 0.0, -1.0), "Y")
nodes["Background"].inputs["Strength"].default_value = background_strength
sun.hide_render = True
result["card_sky_only"] = look("card_sky_only", (0.0, 0.0, -1.0), "Y")
print("RESULT " + json.dumps(result))
