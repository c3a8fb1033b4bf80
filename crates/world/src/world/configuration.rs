//! Configuration trees (`sim.getConfigurationTree` / `sim.setConfigurationTree`): a
//! byte blob holding the local pose of an object and of everything below it, and the
//! positions of the joints among them, to put that part of the scene back later.
//!
//! The blob is gantry's own: only a round trip through the same world is promised, as
//! with CoppeliaSim, whose blob is an opaque buffer too. It is checked whole before
//! anything changes, so bytes that were not made by [`World::configuration_tree`] (cut,
//! edited, or naming objects that are gone or are now of another kind) are refused with
//! a message and leave the scene as it was.
//!
//! Layout, little-endian: the 8-byte [`MAGIC`], the entry count (`u32`), the entries,
//! then an FNV-1a hash (`u64`) of everything before it. An entry is the handle (`i64`),
//! the object type code (`u8`, `sim.object_*_type`), the local pose (x, y, z in m, then
//! the quaternion x, y, z, w; 7 `f64`) and, for a joint only, its position (`f64`, rad
//! or m). Entries are parents first.

use super::object::{Handle, KinematicMotion, ObjectKind};
use super::world::World;
use crate::error::SimError;
use crate::math::{Pose, Quat, Vec3};

/// The first bytes of every configuration tree, the last one the layout's version.
const MAGIC: &[u8; 8] = b"gntyCFG\x01";

/// Bytes of an entry before the joint position.
const ENTRY: usize = 8 + 1 + 7 * 8;

/// One object's saved state.
struct Entry {
    handle: Handle,
    local: Pose,
    joint_position: Option<f64>,
}

fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

fn refused(why: impl std::fmt::Display) -> SimError {
    SimError::BadArgument(format!(
        "not a configuration tree of this scene ({why}); pass what sim.getConfigurationTree returned"
    ))
}

/// A cursor over the blob that fails with a message instead of panicking on short input.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N], SimError> {
        let end = self.at.checked_add(N).filter(|&e| e <= self.bytes.len());
        let end = end.ok_or_else(|| refused("it ends too early"))?;
        let mut out = [0; N];
        out.copy_from_slice(&self.bytes[self.at..end]);
        self.at = end;
        Ok(out)
    }

    fn f64(&mut self) -> Result<f64, SimError> {
        let v = f64::from_le_bytes(self.take()?);
        if v.is_finite() {
            Ok(v)
        } else {
            Err(refused("it holds a non-finite number"))
        }
    }
}

impl World {
    /// The configuration tree of `root` and every object below it, or of the whole scene
    /// for `None` (`sim.handle_scene`): a magic number, then per object (parents first)
    /// its handle, type, local pose and, for a joint, its position, then a check sum.
    ///
    /// # Errors
    /// `root` names no object.
    pub fn configuration_tree(&self, root: Option<Handle>) -> Result<Vec<u8>, SimError> {
        let tops = match root {
            Some(h) => {
                self.object(h)?;
                vec![h]
            }
            None => self.roots().to_vec(),
        };
        let list = self.subtrees(&tops);
        let mut out = Vec::with_capacity(16 + list.len() * (ENTRY + 8));
        out.extend_from_slice(MAGIC);
        // A scene has far fewer than 2^32 objects (handles are table indices).
        out.extend_from_slice(&(list.len() as u32).to_le_bytes());
        for h in list {
            let o = &self.objects[h as usize];
            out.extend_from_slice(&h.to_le_bytes());
            out.push(o.kind.type_code() as u8);
            let t = o.local.translation.vector;
            let q = o.local.rotation.coords;
            for v in [t.x, t.y, t.z, q.x, q.y, q.z, q.w] {
                out.extend_from_slice(&v.to_le_bytes());
            }
            if let ObjectKind::Joint(j) = &o.kind {
                out.extend_from_slice(&j.position.to_le_bytes());
            }
        }
        let hash = fnv1a(&out);
        out.extend_from_slice(&hash.to_le_bytes());
        Ok(out)
    }

    /// Puts back what [`World::configuration_tree`] saved: each object's local pose and
    /// each joint's position, with the velocities of the joints zeroed and the dynamics
    /// of the restored part restarted at rest, as CoppeliaSim resets its dynamic bodies.
    /// Objects created below the saved root since then keep their place relative to
    /// their parent. Joint targets are left as they are.
    ///
    /// # Errors
    /// The bytes are not a configuration tree, or name an object that was removed or is
    /// of another kind than when saved; then nothing changes.
    pub fn set_configuration_tree(&mut self, bytes: &[u8]) -> Result<(), SimError> {
        let entries = self.parse_configuration_tree(bytes)?;
        for e in &entries {
            let o = &mut self.objects[e.handle as usize];
            o.local = e.local;
            if let (ObjectKind::Joint(j), Some(q)) = (&mut o.kind, e.joint_position) {
                j.position = j.constrain(q);
                j.velocity = 0.0;
                j.motion = KinematicMotion::Still;
                if j.max_velocity.is_some() {
                    j.reference = j.position;
                    j.reference_velocity = 0.0;
                }
            }
        }
        // The tops: saved objects whose parent was not saved with them (the root, in
        // general; every live entry is its own top if the tree was re-parented since).
        let saved: std::collections::HashSet<Handle> = entries.iter().map(|e| e.handle).collect();
        let tops: Vec<Handle> = entries
            .iter()
            .map(|e| e.handle)
            .filter(|&h| self.objects[h as usize].parent.is_none_or(|p| !saved.contains(&p)))
            .collect();
        for &h in &tops {
            self.refresh_subtree(h);
        }
        self.rebuild_physics(&tops);
        Ok(())
    }

    /// Reads and checks a whole configuration tree against the scene as it is now.
    fn parse_configuration_tree(&self, bytes: &[u8]) -> Result<Vec<Entry>, SimError> {
        if bytes.len() < MAGIC.len() + 4 + 8 || &bytes[..MAGIC.len()] != MAGIC {
            return Err(refused("it does not start as one"));
        }
        let (body, hash) = bytes.split_at(bytes.len() - 8);
        let mut hash_bytes = [0; 8];
        hash_bytes.copy_from_slice(hash);
        if fnv1a(body) != u64::from_le_bytes(hash_bytes) {
            return Err(refused("its check sum does not match: it was cut or changed"));
        }
        let mut r = Reader {
            bytes: body,
            at: MAGIC.len(),
        };
        let count = u32::from_le_bytes(r.take()?) as usize;
        // Each entry takes at least ENTRY bytes: a count beyond that is a lie, and must
        // not size an allocation.
        if count > body.len() / ENTRY {
            return Err(refused("its object count exceeds its length"));
        }
        let mut entries = Vec::with_capacity(count);
        for _ in 0..count {
            let handle = i64::from_le_bytes(r.take()?);
            let [code] = r.take::<1>()?;
            let object = self
                .object(handle)
                .map_err(|_| refused(format!("object {handle} does not exist")))?;
            if i64::from(code) != object.kind.type_code() {
                return Err(refused(format!(
                    "object {handle} is a {} now, of type {} when saved",
                    object.kind.name(),
                    code
                )));
            }
            let t = Vec3::new(r.f64()?, r.f64()?, r.f64()?);
            let (x, y, z, w) = (r.f64()?, r.f64()?, r.f64()?, r.f64()?);
            // Quaternion::new takes w first; the blob stores x, y, z, w.
            let q = nalgebra::Quaternion::new(w, x, y, z);
            if (q.norm() - 1.0).abs() > 1e-6 {
                return Err(refused(format!(
                    "object {handle}'s orientation is not a unit quaternion"
                )));
            }
            let joint_position = match object.kind {
                ObjectKind::Joint(_) => Some(r.f64()?),
                _ => None,
            };
            entries.push(Entry {
                handle,
                local: Pose::from_parts(t.into(), Quat::new_unchecked(q)),
                joint_position,
            });
        }
        if r.at != body.len() {
            return Err(refused("it has bytes after its last object"));
        }
        Ok(entries)
    }
}
