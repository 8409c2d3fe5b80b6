# What a user would do instead of skybake's W3 (issue 15): Blender Cycles
# rendering a comparable cloud layer under its Nishita sky into one
# 2048 x 1024 equirectangular panorama, at a given sample count, into a
# float EXR. The layer is W3's: a slab from 1.5 to 3 km above the camera,
# 60 km wide, whose density is a noise texture thresholded to about the
# coverage 0.45 of W3 (Principled Volume, extinction 0.05 per metre at full
# density, white albedo), lit by a sun lamp at 45 degrees and the sky; the
# camera on the ground at the slab's centre. Blender units are metres.
#
#   blender -b --factory-startup --python tests/benchmark/blender_clouds.py -- OUT.exr SAMPLES [WIDTH]
#
# The whole process is timed by the caller (docs/performance.md, "W3");
# the noise of a render is measured against a render with more samples
# (oiiotool --diff). The density model differs from skybake's (Blender's
# Perlin noise, not Nubis' Perlin-Worley), so only the cost and the
# noise of a comparable scene are compared.
import math
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from blender_scene import cycles_cpu_scene, make_equirectangular, nishita_world  # noqa: E402

argv = sys.argv[sys.argv.index("--") + 1:]
out_path, samples = argv[0], int(argv[1])
width = int(argv[2]) if len(argv) > 2 else 2048

scene = cycles_cpu_scene(samples)
scene.cycles.seed = samples  # renders of different sample counts are independent (their difference is noise)
scene.cycles.volume_step_rate = 1.0
scene.cycles.volume_max_steps = 1024
scene.render.resolution_x = width
scene.render.resolution_y = width // 2
scene.render.resolution_percentage = 100
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
scene.render.image_settings.color_mode = "RGB"
scene.render.filepath = out_path

# The sky: Nishita, sun at 45 degrees (W3's), its disc on.
sky = nishita_world(scene, bpy.data.worlds.new("sky"))
sky.sun_elevation = math.radians(45.0)
sky.sun_rotation = 0.0

# The Sun as a lamp too, so that the volume is lit by it directly.
sun_data = bpy.data.lights.new("sun", "SUN")
sun_data.energy = 5.0
sun_data.angle = math.radians(0.545)
sun = bpy.data.objects.new("sun", sun_data)
sun.rotation_euler = (math.radians(45.0), 0.0, 0.0)
scene.collection.objects.link(sun)

# The cloud layer: a 60 km x 60 km x 1.5 km box from 1.5 km up.
bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.0, 0.0, 2250.0))
slab = bpy.context.active_object
slab.scale = (60000.0, 60000.0, 1500.0)
material = bpy.data.materials.new("cloud")
material.use_nodes = True
mn = material.node_tree.nodes
mn.clear()
coord = mn.new("ShaderNodeTexCoord")
noise = mn.new("ShaderNodeTexNoise")
noise.inputs["Scale"].default_value = 40.0  # over the box's object space: features of about 1.5 km
noise.inputs["Detail"].default_value = 8.0
ramp = mn.new("ShaderNodeValToRGB")
ramp.color_ramp.elements[0].position = 0.5  # about coverage 0.45
ramp.color_ramp.elements[1].position = 0.6
volume = mn.new("ShaderNodeVolumePrincipled")
volume.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
math_node = mn.new("ShaderNodeMath")
math_node.operation = "MULTIPLY"
math_node.inputs[1].default_value = 0.05  # extinction per metre at full density
out = mn.new("ShaderNodeOutputMaterial")
links = material.node_tree.links
links.new(coord.outputs["Object"], noise.inputs["Vector"])
links.new(noise.outputs["Fac"], ramp.inputs["Fac"])
links.new(ramp.outputs["Color"], math_node.inputs[0])
links.new(math_node.outputs["Value"], volume.inputs["Density"])
links.new(volume.outputs["Volume"], out.inputs["Volume"])
slab.data.materials.append(material)

cam_data = bpy.data.cameras.new("pano")
make_equirectangular(cam_data)
cam_data.clip_end = 1e6
cam = bpy.data.objects.new("pano", cam_data)
cam.location = (0.0, 0.0, 2.0)
cam.rotation_euler = (math.pi / 2, 0.0, 0.0)
scene.collection.objects.link(cam)
scene.camera = cam

bpy.ops.render.render(write_still=True)
