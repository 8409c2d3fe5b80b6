# Blender's glTF importer on a skybake scene (tests/e2e/sequence_test.cc):
#   blender -b --factory-startup --python blender_import_scene.py -- SCENE
# Prints one line:
#   RESULT {"objects": [...], "lights": [[name, type]...], "fcurves": [data paths of every action]}
import json
import sys

import numpy

numpy.bool = bool  # Debian 12's Blender 3.4 glTF importer uses np.bool, gone from numpy 1.24

import bpy

scene_path = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
if bpy.ops.import_scene.gltf(filepath=scene_path) != {"FINISHED"}:
    sys.exit(f"the importer did not finish {scene_path}")
result = {
    "objects": sorted(o.name for o in bpy.data.objects),
    "lights": sorted([o.name, o.data.type] for o in bpy.data.objects if o.type == "LIGHT"),
    "fcurves": sorted({fc.data_path for a in bpy.data.actions for fc in a.fcurves}),
}
print("RESULT " + json.dumps(result))
