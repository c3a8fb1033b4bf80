//! Colour-coded twins: a colour-coded sensor that sees exactly what the sensor rendered
//! just before it saw takes that render's depth and id buffers instead of drawing them.
//!
//! RLBench pairs each of its five cameras with a colour-coded twin at the same pose
//! (`cam_front` and `cam_front_mask`, ...) and renders both every step through PyRep,
//! one `handleVisionSensor` after the other: ten renders for five views. A
//! colour-coded image and its depth are functions of the depth and id buffers alone,
//! and those depend only on the camera's geometry, its world pose and what is drawn
//! (never on colours, textures or lights), so the twin's render is the one just made.
//!
//! "Exactly" is checked, not assumed: [`ViewKey`] holds the simulation step, the world's
//! scene and geometry revisions, the camera's size, extent and clipping planes, the
//! sensor's pose to the bit, and a fingerprint of every drawn visual's handle and pose;
//! any difference and the twin is drawn as any sensor is. The first time a twin is
//! recognised its source drew no ids: the source is then asked to draw them from its
//! next render on (one word per pixel) and to keep a copy of its buffers, and the twin
//! is drawn in full that once.

use std::collections::BTreeSet;
use std::hash::{DefaultHasher, Hash, Hasher};

use super::raster::{Camera, DrawItem, FrameBuffers};
use crate::math::Pose;
use crate::world::{Handle, World};

/// What a render's depth and ids depend on.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct ViewKey {
    step: u64,
    revisions: [u64; 2],
    /// Width, height, orthographic, then the bits of the half extents and the clipping
    /// distances.
    camera: [u64; 7],
    /// The sensor's world pose: translation and quaternion, bits.
    pose: [u64; 7],
    /// Every drawn visual's handle, world pose and tessellation, hashed.
    items: u64,
}

impl ViewKey {
    pub fn new(world: &World, cam: &Camera, pose: &Pose, items: &[DrawItem<'_>]) -> Self {
        let mut h = DefaultHasher::new();
        for item in items {
            item.handle.hash(&mut h);
            pose_bits(&item.pose).hash(&mut h);
            std::ptr::from_ref(item.visual).hash(&mut h);
        }
        Self {
            step: world.steps(),
            revisions: [world.scene_revision(), world.geometry_revision()],
            camera: [
                cam.width as u64,
                cam.height as u64,
                u64::from(cam.ortho),
                u64::from(cam.tan_x.to_bits()),
                u64::from(cam.tan_y.to_bits()),
                u64::from(cam.near.to_bits()),
                u64::from(cam.far.to_bits()),
            ],
            pose: pose_bits(pose),
            items: h.finish(),
        }
    }
}

fn pose_bits(p: &Pose) -> [u64; 7] {
    let t = p.translation.vector;
    let q = p.rotation.coords;
    [t.x, t.y, t.z, q.x, q.y, q.z, q.w].map(f64::to_bits)
}

/// The last single-sensor render, and which sensors have twins.
#[derive(Debug, Clone, Default)]
pub(super) struct LastView {
    key: Option<ViewKey>,
    source: Handle,
    /// The source's depth and id buffers, kept only for sources with a twin (empty
    /// otherwise, or when the render drew no ids).
    zbuf: Vec<f32>,
    ids: Vec<u32>,
    /// Sensors a twin was seen for: their renders draw ids and are kept.
    with_twin: BTreeSet<Handle>,
    /// Renders saved so far (read by the tests).
    pub reuses: u64,
}

/// What to do with a colour-coded sensor about to render.
pub(super) enum TwinOutcome {
    /// Draw it.
    Draw,
    /// Its view is the last one's, and these are that render's buffers.
    Reuse,
    /// Its view is the last one's, whose source drew no ids: draw it, and let that
    /// source draw ids from now on.
    DrawAndTeach(Handle),
}

impl LastView {
    /// Whether a colour-coded sensor seeing `key` can take the last render's buffers.
    pub fn check(&mut self, key: &ViewKey) -> TwinOutcome {
        if self.key.as_ref() != Some(key) {
            return TwinOutcome::Draw;
        }
        if !self.ids.is_empty() {
            self.reuses += 1;
            return TwinOutcome::Reuse;
        }
        self.with_twin.insert(self.source);
        TwinOutcome::DrawAndTeach(self.source)
    }

    /// Whether `h` has a twin (and so should draw ids).
    pub fn has_twin(&self, h: Handle) -> bool {
        self.with_twin.contains(&h)
    }

    /// Puts the kept buffers into `frame` for a colour-coded render of `cam`.
    pub fn load(&self, cam: &Camera, frame: &mut FrameBuffers) {
        frame.load_depth_ids(cam, &self.zbuf, &self.ids);
    }

    /// Records the render of `source` just drawn into `frame` (`pixels` of them).
    pub fn remember(&mut self, key: ViewKey, source: Handle, frame: &FrameBuffers, pixels: usize) {
        self.zbuf.clear();
        self.ids.clear();
        if self.with_twin.contains(&source) {
            frame.copy_depth_ids(pixels, &mut self.zbuf, &mut self.ids);
        }
        self.key = Some(key);
        self.source = source;
    }

    /// Several sensors were drawn at once, or the render was not one to keep.
    pub fn forget(&mut self) {
        self.key = None;
        self.zbuf.clear();
        self.ids.clear();
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::super::{VisionStates, handle_vision_sensor};
    use crate::math::Pose;
    use crate::scene::{EmbeddedFiles, LoadOptions, load_scene_text};
    use crate::{Handle, Sim};

    /// Shapes before a shaded camera and its colour-coded twin at the same pose, and a
    /// second colour-coded camera elsewhere.
    fn scene() -> Sim {
        let mut text = String::new();
        for (k, (x, y, z)) in [(2.0, 0.0, 0.3), (2.5, 0.4, 0.2), (1.6, -0.5, 0.5)].iter().enumerate() {
            text += &format!(
                "[[object]]\nname = \"s{k}\"\nkind = \"shape\"\nshape = \"box\"\nsize = [0.3, 0.4, 0.5]\n\
                 position = [{x}, {y}, {z}]\norientation_deg = [10, 20, {}]\n\n",
                30 * k
            );
        }
        for (name, mode, y) in [
            ("cam", "visible", 0.0),
            ("mask", "color_coded", 0.0),
            ("other", "color_coded", 0.1),
        ] {
            text += &format!(
                "[[object]]\nname = \"{name}\"\nkind = \"vision_sensor\"\nresolution = [64, 48]\nfov_deg = 60\n\
                 near = 0.05\nfar = 5\nrender_mode = \"{mode}\"\nposition = [0, {y}, 0.4]\n\
                 orientation_deg = [0, 90, 0]\n\n"
            );
        }
        let model = load_scene_text(
            &EmbeddedFiles::default(),
            &text,
            Path::new("/t.toml"),
            &LoadOptions::default(),
        )
        .expect("the scene loads");
        Sim::new(&model)
    }

    fn find(w: &Sim, name: &str) -> Handle {
        w.world.find(&format!("/{name}"), None, 0).expect(name)
    }

    fn image(states: &VisionStates, h: Handle) -> (Vec<u8>, Vec<u32>) {
        let img = states.image(h).expect("rendered");
        (img.rgb().to_vec(), img.depth().iter().map(|d| d.to_bits()).collect())
    }

    /// The twin's image drawn on its own, in fresh states.
    fn drawn_alone(w: &Sim, h: Handle) -> (Vec<u8>, Vec<u32>) {
        let mut states = VisionStates::default();
        handle_vision_sensor(&w.world, &mut states, h).expect("render");
        image(&states, h)
    }

    #[test]
    fn a_colour_coded_twin_takes_the_buffers_of_the_view_just_drawn_and_only_that_view() {
        let mut w = scene();
        let (cam, mask, other) = (find(&w, "cam"), find(&w, "mask"), find(&w, "other"));
        let truth = drawn_alone(&w, mask);
        assert!(truth.0.chunks(3).any(|p| p != [255, 255, 255]), "the twin sees shapes");
        let mut states = VisionStates::default();
        let mut reused = Vec::new();
        for _ in 0..3 {
            handle_vision_sensor(&w.world, &mut states, cam).expect("render");
            handle_vision_sensor(&w.world, &mut states, mask).expect("render");
            assert_eq!(image(&states, mask), truth, "the same bits as drawn alone");
            reused.push(states.last_view.reuses);
        }
        // The first time teaches the camera to draw ids; from the second on, reused.
        assert_eq!(reused, [0, 1, 2]);

        // Another view (a different pose), or the world moved in between: drawn.
        handle_vision_sensor(&w.world, &mut states, cam).expect("render");
        handle_vision_sensor(&w.world, &mut states, other).expect("render");
        assert_eq!(image(&states, other), drawn_alone(&w, other));
        handle_vision_sensor(&w.world, &mut states, cam).expect("render");
        let s0 = find(&w, "s0");
        w.world
            .set_world_pose(s0, Pose::translation(1.2, 0.1, 0.4))
            .expect("pose");
        handle_vision_sensor(&w.world, &mut states, mask).expect("render");
        assert_eq!(states.last_view.reuses, 2, "nothing reused since");
        let moved = drawn_alone(&w, mask);
        assert_ne!(moved, truth);
        assert_eq!(image(&states, mask), moved);
    }
}
