# The same work as skybake's W1/W2 benchmark, done the way it is done today
# without skybake: Blender (Cycles, Nishita sky texture, 1 sample per pixel)
# renders a 2048 x 1024 equirectangular latlong and six 512^2 cube faces
# (90-degree perspective cameras) per frame as an animation, into half-float
# ZIP EXRs. The sun's elevation and azimuth are keyframed per frame from a
# skybake manifest, so both tools bake the same sun positions.
#
#   blender -b --factory-startup --python tests/benchmark/blender_sky.py -- MANIFEST OUT_DIR [FRAMES]
#
# Run by tests/benchmark/performance.py, which times the whole Blender
# process. Blender's Z is up; the sky model differs from skybake's (Nishita
# 1993 with Blender's own constants), so only the cost is compared.
import json
import math
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from blender_scene import cycles_cpu_scene, make_equirectangular, nishita_world  # noqa: E402

argv = sys.argv[sys.argv.index("--") + 1:]
manifest_path, out_dir = argv[0], argv[1]
with open(manifest_path) as f:
    frames = json.load(f)["frames"]
if len(argv) > 2:
    frames = frames[: int(argv[2])]

scene = cycles_cpu_scene(1)
scene.render.use_persistent_data = True  # keeps the scene between frames, as an animation render does
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "16"
scene.render.image_settings.exr_codec = "ZIP"
scene.render.image_settings.color_mode = "RGB"
scene.render.resolution_percentage = 100
scene.frame_start = 1
scene.frame_end = len(frames)

# The world: a Nishita sky with its sun disc, keyframed per frame.
sky = nishita_world(scene, bpy.data.worlds.new("sky") if scene.world is None else scene.world)
sky.altitude = 0.0
for i, frame in enumerate(frames, start=1):
    sky.sun_elevation = math.radians(frame["sun"]["elevation_deg"])
    sky.sun_rotation = math.radians(frame["sun"]["azimuth_deg"])
    sky.keyframe_insert("sun_elevation", frame=i)
    sky.keyframe_insert("sun_rotation", frame=i)


def camera(name, rotation, panorama):
    data = bpy.data.cameras.new(name)
    if panorama:
        make_equirectangular(data)
    else:
        data.type = "PERSP"
        data.angle = math.pi / 2
    obj = bpy.data.objects.new(name, data)
    obj.rotation_euler = rotation
    scene.collection.objects.link(obj)
    return obj


half = math.pi / 2
views = [("latlong", (half, 0.0, 0.0), True, 2048, 1024)]
for name, rotation in [("px", (half, 0.0, -half)), ("nx", (half, 0.0, half)), ("py", (half, 0.0, 0.0)),
                       ("ny", (half, 0.0, math.pi)), ("pz", (math.pi, 0.0, 0.0)), ("nz", (0.0, 0.0, 0.0))]:
    views.append((name, rotation, False, 512, 512))

for name, rotation, panorama, width, height in views:
    scene.camera = camera(name, rotation, panorama)
    scene.render.resolution_x = width
    scene.render.resolution_y = height
    scene.render.filepath = os.path.join(out_dir, f"blender_{name}_####")
    bpy.ops.render.render(animation=True)
