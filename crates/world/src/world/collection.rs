//! Collections: named sets of objects built from items (single objects, trees, chains),
//! evaluated against the current tree when queried.

use super::object::Handle;
use crate::scene::{CollectionItemModel, CollectionModel, CollectionScope};

/// The first collection handle; collections and objects never share handles.
pub const FIRST_COLLECTION_HANDLE: Handle = 2_000_000;

/// How an item adds objects to a collection (CoppeliaSim's `sim.handle_*` values).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ItemKind {
    /// One object (`sim.handle_single`, -8).
    Single,
    /// Every object (`sim.handle_all`, -2).
    All,
    /// The object and all its descendants (`sim.handle_tree`, -6).
    Tree,
    /// The object and all its ancestors (`sim.handle_chain`, -7).
    Chain,
}

/// One item of a collection.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CollectionItem {
    /// What the item covers.
    pub kind: ItemKind,
    /// The base object (ignored for `All`).
    pub object: Handle,
    /// Remove the objects instead of adding them (options bit 0).
    pub remove: bool,
    /// Leave out the tree base or chain tip itself (options bit 1).
    pub exclude_base: bool,
}

/// A collection: its items, applied in order.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Collection {
    /// The name V-REP 3's `sim.createCollection(name, options)` gave it, by which
    /// `sim.getCollectionHandle` finds it; empty for the unnamed collections of 4.x.
    pub name: String,
    /// Items in the order they were added.
    pub items: Vec<CollectionItem>,
}

impl Collection {
    /// A scene's collection, its object indices mapped to handles by `handle`.
    pub fn from_model(model: &CollectionModel, handle: impl Fn(usize) -> Handle) -> Self {
        Collection {
            name: model.name.clone(),
            items: model
                .items
                .iter()
                .map(|i| CollectionItem {
                    kind: match i.scope {
                        CollectionScope::Object => ItemKind::Single,
                        CollectionScope::Tree => ItemKind::Tree,
                        CollectionScope::Chain => ItemKind::Chain,
                        CollectionScope::All => ItemKind::All,
                    },
                    object: i.object.map_or(-1, &handle),
                    remove: i.remove,
                    exclude_base: i.exclude_base,
                })
                .collect(),
        }
    }

    /// The collection as a scene's, its handles mapped to object indices by `index`;
    /// `None` when it is unnamed (scene files hold named collections) or an item's
    /// object has no index.
    pub fn to_model(&self, index: impl Fn(Handle) -> Option<usize>) -> Option<CollectionModel> {
        if self.name.is_empty() {
            return None;
        }
        let items = self
            .items
            .iter()
            .map(|i| {
                let (scope, object) = match i.kind {
                    ItemKind::Single => (CollectionScope::Object, Some(index(i.object)?)),
                    ItemKind::Tree => (CollectionScope::Tree, Some(index(i.object)?)),
                    ItemKind::Chain => (CollectionScope::Chain, Some(index(i.object)?)),
                    ItemKind::All => (CollectionScope::All, None),
                };
                Some(CollectionItemModel {
                    scope,
                    object,
                    remove: i.remove,
                    exclude_base: i.exclude_base,
                })
            })
            .collect::<Option<Vec<_>>>()?;
        Some(CollectionModel {
            name: self.name.clone(),
            items,
        })
    }
}
