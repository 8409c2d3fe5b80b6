# What the Blender comparisons (blender_sky.py, blender_clouds.py) set up
# alike: Cycles on the CPU with neither denoising nor adaptive sampling, an
# empty scene, a Nishita sky as the world, equirectangular cameras. Imported
# by those scripts inside Blender (bpy).
import bpy


def cycles_cpu_scene(samples):
    """The scene, emptied of objects, rendered by Cycles on the CPU with `samples` per pixel."""
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    return scene


def nishita_world(scene, world):
    """`world` made the scene's: a Nishita sky, its sun disc on, as the background. Returns the sky node."""
    scene.world = world
    world.use_nodes = True
    nodes = world.node_tree.nodes
    nodes.clear()
    sky = nodes.new("ShaderNodeTexSky")
    sky.sky_type = "NISHITA"
    sky.sun_disc = True
    background = nodes.new("ShaderNodeBackground")
    output = nodes.new("ShaderNodeOutputWorld")
    world.node_tree.links.new(sky.outputs["Color"], background.inputs["Color"])
    world.node_tree.links.new(background.outputs["Background"], output.inputs["Surface"])
    return sky


def make_equirectangular(camera_data):
    """Camera data as an equirectangular panorama (the setting moved between Blender versions)."""
    camera_data.type = "PANO"
    if hasattr(camera_data, "panorama_type"):
        camera_data.panorama_type = "EQUIRECTANGULAR"
    else:
        camera_data.cycles.panorama_type = "EQUIRECTANGULAR"
