//! The editor's undo history: each edit (a batch of `sim.*` calls made while the
//! simulation is stopped, [`crate::Input::Edit`]) keeps a copy of the scene as it was
//! before, which an undo puts back; the scene it replaces goes on the redo list.
//!
//! Copies rather than inverse operations: every registry function is an edit the
//! editor may make, and a copy undoes each of them exactly, with the same handles,
//! without a hand-written inverse per function to get wrong. A copy shares meshes and
//! textures with the scene (they are reference counted), so it costs about a kilobyte
//! per object; [`HISTORY_STEPS`] bounds how many are kept.

use std::collections::VecDeque;

use crate::scene_copy::SceneCopy;

/// Edits kept for undo; the oldest goes when a new one would exceed it.
pub const HISTORY_STEPS: usize = 200;

/// One undoable step: its label and the scene on the other side of it.
pub(crate) struct Entry {
    pub label: String,
    pub scene: SceneCopy,
}

/// The undo and redo lists.
#[derive(Default)]
pub(crate) struct History {
    undo: VecDeque<Entry>,
    redo: Vec<Entry>,
}

impl History {
    /// Records an edit named `label`, `before` being the scene before it; the redo list
    /// is dropped, as in every editor.
    pub(crate) fn record(&mut self, label: &str, before: SceneCopy) {
        self.redo.clear();
        if self.undo.len() == HISTORY_STEPS {
            self.undo.pop_front();
        }
        self.undo.push_back(Entry {
            label: label.to_owned(),
            scene: before,
        });
    }

    /// The step an undo goes back over, if any.
    pub(crate) fn take_undo(&mut self) -> Option<Entry> {
        self.undo.pop_back()
    }

    /// The step a redo goes forward over, if any.
    pub(crate) fn take_redo(&mut self) -> Option<Entry> {
        self.redo.pop()
    }

    /// After an undo: the scene it replaced, to redo.
    pub(crate) fn push_redo(&mut self, entry: Entry) {
        self.redo.push(entry);
    }

    /// After a redo: the scene it replaced, to undo again.
    pub(crate) fn push_undo(&mut self, entry: Entry) {
        self.undo.push_back(entry);
    }

    /// How many edits can be undone and redone.
    pub(crate) fn depth(&self) -> (usize, usize) {
        (self.undo.len(), self.redo.len())
    }

    /// Forgets everything (a new scene).
    pub(crate) fn clear(&mut self) {
        self.undo.clear();
        self.redo.clear();
    }
}
