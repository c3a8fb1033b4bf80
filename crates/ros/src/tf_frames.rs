//! Which frames of the object tree go on `/tf_static` and which on `/tf`, and the
//! `tf2_msgs/TFMessage`s of a snapshot: one rule for the recording and the live ROS 2
//! graph. A frame is static until its parent changes or its pose differs from the value
//! it had on `/tf_static` (bit for bit in a recording, which reads back exactly; by more
//! than [`STATIC_TOLERANCE`] on the live graph), and moving from then on; `/tf_static` is published again,
//! whole, whenever its set changes, as ROS's latched topic expects.

use std::collections::{BTreeMap, HashSet};

use gantry_protocol::ros::typed::{self as msg, Time, TransformStamped, WORLD_FRAME};

use crate::snapshot::Snapshot;

/// How far (m, and in each quaternion component) a frame may stray from its
/// `/tf_static` pose and stay static. A part fixed to a moving body (a sensor on a
/// rover) has a constant pose relative to it, but computed from two world poses each
/// step it wanders in the last bits; a nanometre is far below anything a consumer of
/// tf resolves and far above that rounding.
pub const STATIC_TOLERANCE: f64 = 1e-9;

/// The static and moving frames seen so far (see the module docs).
#[derive(Debug, Clone, Default)]
pub struct TfFrames {
    /// How far a static frame may stray, m and quaternion components; 0: bit for bit.
    tolerance: f64,
    /// The frames on `/tf_static`, by child frame id: parent frame id and pose of
    /// each frame that has not moved relative to its parent since the first snapshot.
    statics: BTreeMap<String, (String, [f64; 7])>,
    /// Frames that have moved at least once: they are on `/tf` from then on.
    moved: HashSet<String>,
}

/// One `geometry_msgs/TransformStamped` of a frame.
fn transform<'a>(stamp: Time, parent: &'a str, child: &'a str, pose: &[f64; 7]) -> TransformStamped<'a> {
    TransformStamped {
        stamp,
        frame_id: parent,
        child_frame_id: child,
        translation: [pose[0], pose[1], pose[2]],
        rotation: [pose[3], pose[4], pose[5], pose[6]],
    }
}

impl TfFrames {
    /// Frames static while their poses stay bit for bit the same (recordings).
    pub fn exact() -> Self {
        Self::default()
    }

    /// Frames static while their poses stay within [`STATIC_TOLERANCE`] (the live graph).
    pub fn tolerant() -> Self {
        Self {
            tolerance: STATIC_TOLERANCE,
            ..Self::default()
        }
    }

    /// The `/tf_static` message when the static set changed with this snapshot, and the
    /// `/tf` message of the moving frames (CDR with its encapsulation header).
    pub fn messages(&mut self, s: &Snapshot) -> (Option<Vec<u8>>, Vec<u8>) {
        let stamp = Time::from_nanos(s.stamp_ns);
        let frame = |h| s.frame(h);
        let frames_now: Vec<(&str, &str, &[f64; 7])> = s
            .poses
            .iter()
            .map(|p| (frame(p.handle), p.parent.map_or(WORLD_FRAME, frame), &p.pose))
            .collect();
        let statics = self.update(&frames_now).then(|| {
            let transforms: Vec<TransformStamped<'_>> = self
                .statics
                .iter()
                .map(|(child, (parent, pose))| transform(stamp, parent, child, pose))
                .collect();
            msg::tf_message(&transforms)
        });
        let transforms: Vec<TransformStamped<'_>> = frames_now
            .iter()
            .filter(|(child, _, _)| self.moved.contains(*child))
            .map(|&(child, parent, pose)| transform(stamp, parent, child, pose))
            .collect();
        (statics, msg::tf_message(&transforms))
    }

    /// Whether two coordinates of a static frame's pose count as the same.
    fn same(&self, a: f64, b: f64) -> bool {
        if self.tolerance > 0.0 {
            (a - b).abs() <= self.tolerance
        } else {
            a.to_bits() == b.to_bits()
        }
    }

    /// Sorts frames `(child, parent, pose)` into static and moving ones; whether the
    /// static set changed (a frame added, removed or moved).
    fn update(&mut self, frames: &[(&str, &str, &[f64; 7])]) -> bool {
        let mut changed = false;
        for &(child, parent, pose) in frames {
            if self.moved.contains(child) {
                continue;
            }
            match self.statics.get(child) {
                Some((p, q)) if p == parent && q.iter().zip(pose).all(|(a, b)| self.same(*a, *b)) => {}
                Some(_) => {
                    self.statics.remove(child);
                    self.moved.insert(child.to_owned());
                    changed = true;
                }
                None => {
                    self.statics.insert(child.to_owned(), (parent.to_owned(), *pose));
                    changed = true;
                }
            }
        }
        // Frames gone from the tree (objects removed, renamed or moved elsewhere).
        if self.statics.len() + frames.iter().filter(|(c, _, _)| self.moved.contains(*c)).count() != frames.len() {
            let present: std::collections::HashSet<&str> = frames.iter().map(|(c, _, _)| *c).collect();
            let before = self.statics.len();
            self.statics.retain(|c, _| present.contains(c.as_str()));
            changed |= self.statics.len() != before;
        }
        changed
    }
}
