//! The object selection (`sim.getObjectSel`, `sim.setObjectSel`): in CoppeliaSim the
//! editor's, in gantry the viewer's, where a click picks an object. Scripts and clients
//! read it and set it; the viewer shows it.

use super::object::Handle;

/// Most objects selected at once.
pub const MAX_SELECTION: usize = 1024;

/// The selected objects, in selection order.
#[derive(Debug, Clone, Default)]
pub struct Selection {
    handles: Vec<Handle>,
    revision: u64,
}

impl Selection {
    /// Replaces the selection (duplicates dropped, order kept; at most
    /// [`MAX_SELECTION`]). The caller checks that the objects exist.
    pub fn set(&mut self, handles: &[Handle]) {
        let mut kept: Vec<Handle> = Vec::with_capacity(handles.len().min(MAX_SELECTION));
        for &h in handles {
            if kept.len() == MAX_SELECTION {
                break;
            }
            if !kept.contains(&h) {
                kept.push(h);
            }
        }
        if kept != self.handles {
            self.handles = kept;
            self.revision += 1;
        }
    }

    /// The selected objects.
    pub fn handles(&self) -> &[Handle] {
        &self.handles
    }

    /// Drops a removed object.
    pub fn forget(&mut self, h: Handle) {
        if self.handles.contains(&h) {
            self.handles.retain(|&x| x != h);
            self.revision += 1;
        }
    }

    /// A counter bumped by every change, for the viewer.
    pub fn revision(&self) -> u64 {
        self.revision
    }
}
