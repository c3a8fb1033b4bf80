//! CoppeliaSim's floating views (`sim.floatingViewAdd`, `sim.adjustView`,
//! `sim.floatingViewRemove`): small windows over the main 3D view that show what a
//! viewable object sees. In gantry they are overlays on the viewer's 3D view showing a
//! vision sensor's image; the viewer draws them, this module keeps them.

use gantry_scene::Handle;

/// Most floating views at once (each is drawn on every viewer page).
pub const MAX_VIEWS: usize = 32;
/// Longest label kept, bytes.
pub const MAX_LABEL_LEN: usize = 256;

/// One floating view.
#[derive(Debug, Clone, PartialEq)]
pub struct FloatingView {
    /// Its handle (`sim.floatingViewAdd`'s result).
    pub handle: i64,
    /// Centre of the view, relative to the main view: 0..1, (0, 0) at the bottom left.
    pub centre: [f64; 2],
    /// Size, relative to the main view: 0..1.
    pub size: [f64; 2],
    /// `sim.floatingViewAdd`'s options (kept; the viewer's views are not closable).
    pub options: i64,
    /// The object whose view it shows (`sim.adjustView`); `None` until associated.
    pub object: Option<Handle>,
    /// The caption (`sim.adjustView`'s label; the object's alias when empty).
    pub label: String,
}

/// Every floating view.
#[derive(Debug, Clone, Default)]
pub struct FloatingViews {
    views: Vec<FloatingView>,
    next: i64,
    revision: u64,
}

/// Why a floating-view call failed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ViewError {
    /// Position or size outside 0..1 (or not finite).
    #[error("position and size are relative to the main view: finite, 0..1 (size above 0)")]
    OutOfRange,
    /// Too many views.
    #[error("at most {MAX_VIEWS} floating views")]
    TooMany,
    /// No such view.
    #[error("no floating view {0}")]
    NoSuchView(i64),
}

impl FloatingViews {
    /// Adds a view (`sim.floatingViewAdd`) and returns its handle.
    ///
    /// # Errors
    /// [`ViewError::OutOfRange`], [`ViewError::TooMany`].
    pub fn add(&mut self, centre: [f64; 2], size: [f64; 2], options: i64) -> Result<i64, ViewError> {
        let unit = |v: f64| v.is_finite() && (0.0..=1.0).contains(&v);
        if !centre.iter().all(|&v| unit(v)) || !size.iter().all(|&v| unit(v) && v > 0.0) {
            return Err(ViewError::OutOfRange);
        }
        if self.views.len() >= MAX_VIEWS {
            return Err(ViewError::TooMany);
        }
        // View handles count from 1 in their own namespace, never reused.
        self.next += 1;
        self.views.push(FloatingView {
            handle: self.next,
            centre,
            size,
            options,
            object: None,
            label: String::new(),
        });
        self.revision += 1;
        Ok(self.next)
    }

    /// Shows `object`'s view in view `handle`, with `label` (`sim.adjustView`).
    ///
    /// # Errors
    /// [`ViewError::NoSuchView`].
    pub fn adjust(&mut self, handle: i64, object: Option<Handle>, label: &str) -> Result<(), ViewError> {
        let v = self
            .views
            .iter_mut()
            .find(|v| v.handle == handle)
            .ok_or(ViewError::NoSuchView(handle))?;
        v.object = object;
        let mut end = label.len().min(MAX_LABEL_LEN);
        while !label.is_char_boundary(end) {
            end -= 1;
        }
        v.label = label[..end].to_owned();
        self.revision += 1;
        Ok(())
    }

    /// Removes view `handle` (`sim.floatingViewRemove`); false when there is none.
    pub fn remove(&mut self, handle: i64) -> bool {
        let before = self.views.len();
        self.views.retain(|v| v.handle != handle);
        let removed = self.views.len() != before;
        if removed {
            self.revision += 1;
        }
        removed
    }

    /// Forgets `object` in every view that showed it (the object was removed).
    pub fn forget_object(&mut self, object: Handle) {
        for v in &mut self.views {
            if v.object == Some(object) {
                v.object = None;
                self.revision += 1;
            }
        }
    }

    /// The views, oldest first.
    pub fn iter(&self) -> impl Iterator<Item = &FloatingView> {
        self.views.iter()
    }

    /// A counter bumped by every change, for the viewer.
    pub fn revision(&self) -> u64 {
        self.revision
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn add_adjust_remove() {
        let mut v = FloatingViews::default();
        let a = v.add([0.9, 0.9], [0.2, 0.2], 0).unwrap();
        let b = v.add([0.7, 0.9], [0.2, 0.2], 1).unwrap();
        assert_ne!(a, b);
        v.adjust(a, Some(5), "floor").unwrap();
        assert_eq!(
            v.iter().next().map(|x| (x.object, x.label.as_str())),
            Some((Some(5), "floor"))
        );
        assert_eq!(v.adjust(99, None, ""), Err(ViewError::NoSuchView(99)));
        assert!(v.remove(a));
        assert!(!v.remove(a));
        assert_eq!(v.iter().count(), 1);
        assert_eq!(v.add([1.5, 0.5], [0.1, 0.1], 0), Err(ViewError::OutOfRange));
        assert_eq!(v.add([0.5, 0.5], [0.0, 0.1], 0), Err(ViewError::OutOfRange));
        assert_eq!(v.add([f64::NAN, 0.5], [0.1, 0.1], 0), Err(ViewError::OutOfRange));
        for _ in 1..MAX_VIEWS {
            v.add([0.5, 0.5], [0.1, 0.1], 0).unwrap();
        }
        assert_eq!(v.add([0.5, 0.5], [0.1, 0.1], 0), Err(ViewError::TooMany));
        let r = v.revision();
        v.forget_object(123);
        assert_eq!(v.revision(), r, "nothing showed object 123");
    }
}
