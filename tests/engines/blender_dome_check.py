# The glTF dome seen through Blender's startup camera (tests/e2e/engine_blender_test.cc):
#   blender -b --factory-startup --python blender_dome_check.py -- SCENE.glb OUT_DIR
# Imports the scene with Blender's glTF importer into the factory startup
# scene (its cube, light and camera, as a user who opens Blender and imports
# it), hides every object but the imported meshes, and renders the startup
# camera as it is (its place, its clip range) with Cycles into a transparent
# film: a pixel whose alpha is 1 shows the dome, one whose alpha is 0 sees
# past it (clipped away, or a hole). Prints one line:
#   RESULT {"clip_start": s, "clip_end": e, "camera_location": [x, y, z],
#           "farthest_vertex_m": d, "covered": f}
# with the dome's vertex farthest from the camera and the fraction of pixels
# that show the dome.
import json
import os
import sys

import numpy

numpy.bool = bool  # Debian 12's Blender 3.4 glTF importer uses np.bool, gone from numpy 1.24

import bpy

scene_path, out_dir = sys.argv[sys.argv.index("--") + 1:][:2]
startup = set(bpy.data.objects.keys())
camera = bpy.context.scene.camera
if camera is None:
    sys.exit("the factory startup scene has no camera")
bpy.ops.import_scene.gltf(filepath=scene_path)
domes = [o for o in bpy.data.objects if o.name not in startup and o.type == "MESH"]
if not domes:
    sys.exit(f"no mesh imported from {scene_path}")
for o in bpy.data.objects:
    if o not in domes and o.type != "CAMERA":
        o.hide_render = True

eye = camera.matrix_world.translation
farthest = max((o.matrix_world @ v.co - eye).length for o in domes for v in o.data.vertices)

scene = bpy.context.scene
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = 1
scene.cycles.use_denoising = False
scene.render.film_transparent = True
scene.render.resolution_percentage = 2  # the startup 1920 x 1080 at 38 x 21
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_mode = "RGBA"
scene.render.image_settings.color_depth = "32"
scene.render.filepath = os.path.join(out_dir, "dome_startup_camera.exr")
bpy.ops.render.render(write_still=True)
image = bpy.data.images.load(scene.render.filepath)
alpha = numpy.array(image.pixels[:]).reshape(-1, 4)[:, 3]
print("RESULT " + json.dumps({"clip_start": camera.data.clip_start, "clip_end": camera.data.clip_end,
                              "camera_location": list(eye), "farthest_vertex_m": farthest,
                              "covered": float((alpha > 0.99).mean())}))
