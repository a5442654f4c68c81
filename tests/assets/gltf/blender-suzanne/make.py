# Writes scene.glb beside this file with Blender's own glTF exporter:
#   blender --background --factory-startup --python tests/assets/gltf/blender-suzanne/make.py
# A scene as a Blender user makes one, objects in creation order: a ground plane first, a crate
# with an image texture (Blender's generated colour grid) on it, then Suzanne, keyframed to move
# across the ground over 2 s; a 1000 W spot light and a camera. The animated object is the last
# node, not the first; the light is written in candela (1000 W -> 54,351 cd).
import math
import os

import numpy

# Debian's Blender 3.4.1 runs against a numpy without the `numpy.bool` alias its glTF add-on uses.
numpy.bool = bool

import bpy

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.fps = 24
scene.frame_start, scene.frame_end = 1, 49

bpy.ops.mesh.primitive_plane_add(size=6, location=(0, 0, 0))
bpy.context.object.name = "Ground"

bpy.ops.mesh.primitive_cube_add(size=1, location=(1.2, -0.4, 0.5))
crate = bpy.context.object
crate.name = "Crate"
grid = bpy.data.images.new("grid", 64, 64)
grid.generated_type = "COLOR_GRID"
material = bpy.data.materials.new("crate")
material.use_nodes = True
texture = material.node_tree.nodes.new("ShaderNodeTexImage")
texture.image = grid
shader = material.node_tree.nodes["Principled BSDF"]
material.node_tree.links.new(texture.outputs["Color"], shader.inputs["Base Color"])
crate.data.materials.append(material)

bpy.ops.mesh.primitive_monkey_add(size=1, location=(-1.5, 0.8, 0.6))
suzanne = bpy.context.object
suzanne.name = "Suzanne"
bpy.ops.object.shade_smooth()
levels = int(os.environ.get("SUBDIVISIONS", "0"))
if levels > 0:
    modifier = suzanne.modifiers.new("subdivision", "SUBSURF")
    modifier.levels = modifier.render_levels = levels
    bpy.ops.object.modifier_apply(modifier=modifier.name)
for frame, x in [(1, -1.5), (49, 1.0)]:
    suzanne.location.x = x
    suzanne.keyframe_insert(data_path="location", frame=frame)

spot = bpy.data.objects.new("Spot", bpy.data.lights.new("Spot", type="SPOT"))
spot.data.energy = 1000.0
spot.data.spot_size = math.radians(70)
spot.location = (2.0, -2.0, 4.0)
spot.rotation_euler = (math.radians(35), 0.0, math.radians(45))
scene.collection.objects.link(spot)

camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
camera.data.lens = 28
camera.location = (0.0, -7.5, 4.5)
camera.rotation_euler = (math.radians(59), 0.0, 0.0)
scene.collection.objects.link(camera)
scene.camera = camera

out = os.environ.get("OUT") or os.path.join(os.path.dirname(os.path.abspath(__file__)), "scene.glb")
bpy.ops.export_scene.gltf(filepath=out, export_format="GLB", export_lights=True, export_cameras=True)
