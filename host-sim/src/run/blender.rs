//! `--blender`: `blender.py` and `speech.wav` in the run folder, so that
//! `blender --python DIR/blender.py` opens the played motion and its speech as one scene.
//!
//! The script uses only what ships with Blender: the BVH importer (`import_anim.bvh`, at the
//! BVH's frame rate, centimetres to metres, Y up) and the video sequencer's sound strip,
//! starting on the animation's first frame so the two play in sync; it sets the scene's
//! range to the motion and points the camera-less viewport at the armature. `speech.wav` is the
//! audio the controller heard (mono, 16-bit, the blob's rate), so the folder is self-contained.

/// The script; it finds its files next to itself.
pub const SCRIPT: &str = r#"# Opens this gesture-sim run in Blender: blender --python blender.py
# (made by `gesture-sim run --blender`; uses only Blender's own BVH importer and sequencer).
import os
import bpy

here = os.path.dirname(os.path.abspath(__file__))
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
bpy.ops.import_anim.bvh(
    filepath=os.path.join(here, "motion.bvh"),
    global_scale=0.01,
    axis_forward="-Z",
    axis_up="Y",
    update_scene_fps=True,
    update_scene_duration=True,
)
scene.frame_start = 1
editor = scene.sequence_editor_create()
strips = getattr(editor, "strips", None) or editor.sequences
strips.new_sound("speech", os.path.join(here, "speech.wav"), 1, 1)
scene.sync_mode = "AUDIO_SYNC"
scene.frame_current = 1
print("gesture-sim run loaded: %d frames at %g fps" % (scene.frame_end, scene.render.fps))
"#;
