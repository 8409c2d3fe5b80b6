# What a user would do instead of skybake's W3 (issue 15): Blender Cycles
# rendering a comparable cloud layer under its Nishita sky into one
# 2048 x 1024 equirectangular panorama, at a given sample count, into a
# float32 ZIP EXR (what `skybake bake` writes with pixel_type = "float").
#
#   blender -b --factory-startup --python tests/benchmark/blender_clouds.py -- OUT.exr SAMPLES
#       [--width 2048] [--seed N] [--sun-elevation 45] [--rows FIRST END] [--clear] [--probe]
#
# --rows renders only the panorama's rows [FIRST, END) (0 the zenith row),
# cropped to them: a strip to measure noise on at less cost.
#
# Run by `tests/benchmark/performance.py --blender-clouds`, which times the
# whole process and measures the noise (docs/performance_history.md, "W3 against
# Blender Cycles"). Blender units are metres, Z is up.
#
# The scene is W3's (configs/benchmark/w3.toml):
# - the Sun at 45 deg elevation (W3's; --sun-elevation), azimuth 135 deg
#   (Blender's sun rotation),
#   Nishita's own sun disc (0.545 deg) as the only sun: Cycles samples the
#   disc of a Nishita sky as a cone, as it samples a sun lamp;
# - one layer from 1.5 to 3 km, 600 km x 600 km (skybake marches clouds to
#   300 km from the viewer), the camera on the ground at its centre;
# - the density written as skybake's (docs/clouds.md, "Density"; Schneider
#   2015) with Blender's Perlin noise in place of skybake's tiled
#   Perlin-Worley volumes: weather w (2D noise, 10 km lattice, spread to
#   mean 0.5, sd 0.25 as skybake's map), local coverage
#   c = clamp(2 x 0.45 - 1 + w, 0, 1), cumulus height profile
#   (0, 0.08, 0.45, 1, smoothstep), shape s (3D noise, 1 km lattice, spread
#   to mean 0.5, sd 0.2 as skybake's shape volume),
#   d = clamp((s p - (1 - c)) / c, 0, 1) c, extinction 0.05 d per metre;
#   no detail erosion;
# - albedo 0.99, the dual-lobe Henyey-Greenstein phase (g 0.7 and -0.2,
#   mixed 0.5) as two Volume Scatter closures of half the scattering each;
# - the march as skybake's production preset: 93.75 m steps (a vertical
#   crossing of the 1.5 km layer in 16 steps), at most 48 per crossing
#   (Cycles: the object's step size 0.1 x its mean bound, 40,050 m, times the
#   material's and the scene's step rates; volume_max_steps = 48); Cycles
#   marches the shadow rays with the same rule (skybake: 24 light samples
#   over at most 8 km);
# - Blender's default volume bounces (0): single scattering of the Sun and
#   the sky, no multiple scattering (skybake approximates it with 8 octaves
#   and an ambient term), the cheapest render Cycles offers for this scene.
#
# --clear renders the sky alone (no layer), the reference the cloud cover is
# measured against. --probe replaces the camera by an orthographic one
# looking down on a plane at 2.25 km that emits the raw noise values (shape
# in R, weather in G): the spread constants below come from it.
import argparse
import math
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from blender_scene import cycles_cpu_scene, make_equirectangular, nishita_world  # noqa: E402

parser = argparse.ArgumentParser()
parser.add_argument("out")
parser.add_argument("samples", type=int)
parser.add_argument("--width", type=int, default=2048)
parser.add_argument("--seed", type=int, default=1)
parser.add_argument("--sun-elevation", type=float, default=45.0)
parser.add_argument("--rows", type=int, nargs=2, default=None)
parser.add_argument("--clear", action="store_true")
parser.add_argument("--probe", action="store_true")
args = parser.parse_args(sys.argv[sys.argv.index("--") + 1:])

LAYER_BOTTOM_M, LAYER_THICKNESS_M, LAYER_HALF_WIDTH_M = 1500.0, 1500.0, 300000.0
COVERAGE, DENSITY_PER_M, ALBEDO = 0.45, 0.05, 0.99
SHAPE_LATTICE_M, WEATHER_LATTICE_M = 1000.0, 10000.0
# Mean and standard deviation of the raw noise values, measured with
# --probe (256 x 256 point samples over 600 km, `oiiotool --stats`; Blender
# 3.4.1): shape 0.4998 and 0.0822, weather 0.4998 and 0.0982. The spreads
# map them to skybake's.
SHAPE_MEAN, SHAPE_SD = 0.5, 0.0822
WEATHER_MEAN, WEATHER_SD = 0.5, 0.0982
STEP_M, MAX_STEPS = LAYER_THICKNESS_M / 16.0, 48

scene = cycles_cpu_scene(args.samples)
scene.cycles.seed = args.seed
scene.cycles.volume_max_steps = MAX_STEPS
scene.render.resolution_x = args.width
scene.render.resolution_y = args.width // 2
scene.render.resolution_percentage = 100
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
scene.render.image_settings.exr_codec = "ZIP"
scene.render.image_settings.color_mode = "RGB"
scene.render.filepath = args.out
if args.rows:
    # Blender's border counts from the bottom, in fractions of the height.
    height = args.width // 2
    scene.render.use_border = True
    scene.render.use_crop_to_border = True
    scene.render.border_min_x, scene.render.border_max_x = 0.0, 1.0
    scene.render.border_min_y = (height - args.rows[1]) / height
    scene.render.border_max_y = (height - args.rows[0]) / height

sky = nishita_world(scene, bpy.data.worlds.new("sky"))
sky.altitude = 0.0
sky.sun_elevation = math.radians(args.sun_elevation)
sky.sun_rotation = math.radians(135.0)


class Graph:
    """A material's node tree, built by small helpers."""

    def __init__(self, material):
        material.use_nodes = True
        self.nodes = material.node_tree.nodes
        self.links = material.node_tree.links
        self.nodes.clear()

    def link(self, source, target, socket):
        self.links.new(source, target.inputs[socket])

    def math(self, operation, a, b=None, clamp=False):
        node = self.nodes.new("ShaderNodeMath")
        node.operation = operation
        node.use_clamp = clamp
        for i, v in enumerate((a, b)):
            if v is None:
                continue
            if isinstance(v, (int, float)):
                node.inputs[i].default_value = v
            else:
                self.links.new(v, node.inputs[i])
        return node.outputs[0]

    def map_range(self, value, lo, hi, to_lo, to_hi, smooth=False):
        node = self.nodes.new("ShaderNodeMapRange")
        node.interpolation_type = "SMOOTHSTEP" if smooth else "LINEAR"
        node.clamp = True
        self.links.new(value, node.inputs["Value"])
        for name, v in (("From Min", lo), ("From Max", hi), ("To Min", to_lo), ("To Max", to_hi)):
            node.inputs[name].default_value = v
        return node.outputs["Result"]

    def noise(self, position, lattice_m, dimensions):
        node = self.nodes.new("ShaderNodeTexNoise")
        node.noise_dimensions = dimensions
        node.inputs["Scale"].default_value = 1.0 / lattice_m
        node.inputs["Detail"].default_value = 3.0  # 4 octaves (skybake's shape: 3 Perlin octaves and Worley)
        node.inputs["Roughness"].default_value = 0.5
        self.links.new(position, node.inputs["Vector"])
        return node.outputs["Fac"]


def noises(g):
    position = g.nodes.new("ShaderNodeNewGeometry").outputs["Position"]
    return position, g.noise(position, SHAPE_LATTICE_M, "3D"), g.noise(position, WEATHER_LATTICE_M, "2D")


def spread(g, fac, mean, sd, to_sd):
    # clamp(0.5 + (fac - mean) to_sd / sd, 0, 1) as a clamped linear map range
    half = 0.5 * sd / to_sd
    return g.map_range(fac, mean - half, mean + half, 0.0, 1.0)


def cloud_material():
    material = bpy.data.materials.new("cloud")
    material.cycles.volume_step_rate = 0.05
    g = Graph(material)
    position, shape_fac, weather_fac = noises(g)
    z = g.nodes.new("ShaderNodeSeparateXYZ")
    g.link(position, z, "Vector")
    hf = g.map_range(z.outputs["Z"], LAYER_BOTTOM_M, LAYER_BOTTOM_M + LAYER_THICKNESS_M, 0.0, 1.0)
    profile = g.math("MULTIPLY", g.map_range(hf, 0.0, 0.08, 0.0, 1.0, smooth=True),
                     g.map_range(hf, 0.45, 1.0, 1.0, 0.0, smooth=True))
    shape = spread(g, shape_fac, SHAPE_MEAN, SHAPE_SD, 0.2)
    weather = spread(g, weather_fac, WEATHER_MEAN, WEATHER_SD, 0.25)
    c = g.math("ADD", weather, 2.0 * COVERAGE - 1.0, clamp=True)
    remapped = g.math("DIVIDE", g.math("ADD", g.math("MULTIPLY", shape, profile), g.math("SUBTRACT", c, 1.0)), c)
    d = g.math("MULTIPLY", g.math("MULTIPLY", remapped, 1.0, clamp=True), c)
    sigma_t = g.math("MULTIPLY", d, DENSITY_PER_M)
    closures = []
    for g_phase in (0.7, -0.2):
        scatter = g.nodes.new("ShaderNodeVolumeScatter")
        scatter.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
        scatter.inputs["Anisotropy"].default_value = g_phase
        g.links.new(g.math("MULTIPLY", sigma_t, 0.5 * ALBEDO), scatter.inputs["Density"])
        closures.append(scatter.outputs[0])
    absorb = g.nodes.new("ShaderNodeVolumeAbsorption")
    absorb.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    g.links.new(g.math("MULTIPLY", sigma_t, 1.0 - ALBEDO), absorb.inputs["Density"])
    closures.append(absorb.outputs[0])
    total = closures[0]
    for other in closures[1:]:
        add = g.nodes.new("ShaderNodeAddShader")
        g.links.new(total, add.inputs[0])
        g.links.new(other, add.inputs[1])
        total = add.outputs[0]
    out = g.nodes.new("ShaderNodeOutputMaterial")
    g.link(total, out, "Volume")
    return material


def probe_material():
    material = bpy.data.materials.new("probe")
    g = Graph(material)
    _, shape_fac, weather_fac = noises(g)
    combine = g.nodes.new("ShaderNodeCombineXYZ")
    g.link(shape_fac, combine, "X")
    g.link(weather_fac, combine, "Y")
    emission = g.nodes.new("ShaderNodeEmission")
    g.link(combine.outputs[0], emission, "Color")
    out = g.nodes.new("ShaderNodeOutputMaterial")
    g.link(emission.outputs[0], out, "Surface")
    return material


def box(name, half_xyz, centre, material):
    bpy.ops.mesh.primitive_cube_add(size=2.0, location=centre)
    obj = bpy.context.active_object
    obj.name = name
    obj.scale = half_xyz
    bpy.ops.object.transform_apply(scale=True)  # bounds in world metres (the step size's base)
    obj.data.materials.append(material)
    return obj


if args.probe:
    bpy.ops.mesh.primitive_plane_add(size=2.0 * LAYER_HALF_WIDTH_M, location=(0.0, 0.0, 2250.0))
    bpy.context.active_object.data.materials.append(probe_material())
    scene.render.resolution_y = args.width
    scene.cycles.filter_width = 0.01  # point samples: the spread of the noise itself, not of pixel means
elif not args.clear:
    box("layer", (LAYER_HALF_WIDTH_M, LAYER_HALF_WIDTH_M, 0.5 * LAYER_THICKNESS_M),
        (0.0, 0.0, LAYER_BOTTOM_M + 0.5 * LAYER_THICKNESS_M), cloud_material())
    # Cycles' step size: 0.1 x the mean bound (40,050 m) x the material's rate
    # (0.05, set above) x the scene's rate; the rates' lower limit is 0.01.
    object_step_m = 0.1 * (4.0 * LAYER_HALF_WIDTH_M + LAYER_THICKNESS_M) / 3.0 * 0.05
    scene.cycles.volume_step_rate = STEP_M / object_step_m
    if abs(scene.cycles.volume_step_rate - STEP_M / object_step_m) > 1e-6:
        raise SystemExit(f"volume_step_rate clamped to {scene.cycles.volume_step_rate}")

cam_data = bpy.data.cameras.new("camera")
if args.probe:
    cam_data.type = "ORTHO"
    cam_data.ortho_scale = 2.0 * LAYER_HALF_WIDTH_M
    cam_data.clip_end = 1e5
else:
    make_equirectangular(cam_data)
    cam_data.clip_end = 1e7
cam = bpy.data.objects.new("camera", cam_data)
cam.location = (0.0, 0.0, 10000.0) if args.probe else (0.0, 0.0, 2.0)
cam.rotation_euler = (0.0, 0.0, 0.0) if args.probe else (math.pi / 2, 0.0, 0.0)
scene.collection.objects.link(cam)
scene.camera = cam

bpy.ops.render.render(write_still=True)
