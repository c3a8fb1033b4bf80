//! The simulated world: the object tree (handles, aliases, parents, f64 poses), its
//! rapier counterpart, CoppeliaSim's path lookup, and editing the scene at run time.
//!
//! This floor knows objects and physics only. What scripts build on top of them
//! (drawings, graphs, UIs, IK environments, vision images, trajectory generators,
//! signals) lives on the floors above, and [`crate::sim::Sim`] owns both.

mod collection;
mod configuration;
mod contacts;
mod containment;
mod custom_data;
mod edit;
mod edit_state;
mod export;
mod group;
mod log;
mod mass;
mod object;
pub mod object_path;
mod octree;
mod particles;
mod physics;
mod point_cloud;
mod properties;
mod property_flags;
mod query;
mod scale;
mod selection;
mod shape_mesh;
mod shape_texture;
mod texture;
mod tuning;
mod urdf_robot;
#[expect(
    clippy::module_inception,
    reason = "the World type's file is named after it, like rapier's rigid_body/rigid_body.rs"
)]
mod world;

pub use collection::{Collection, CollectionItem, FIRST_COLLECTION_HANDLE, ItemKind};
pub use contacts::Contact;
pub use custom_data::CustomData;
pub use edit::MIN_SHAPE_MASS;
pub use edit_state::{ColorComponent, EditCounters};
pub use export::ExportedScene;
pub use log::{LOG_CAPACITY, Log, LogLine};
pub use mass::MassProperties;
pub use object::{Detection, ForceReading, Handle, Joint, KinematicMotion, Object, ObjectKind, ProximitySensor};
pub use octree::{DEFAULT_VOXEL_COLOR, MAX_OCTREE_VOXELS, MAX_VOXEL_INDEX, Octree, Triangle, VOXEL_TOLERANCE, Voxel};
pub use particles::{
    FIRST_PARTICLE_HANDLE, MAX_LIVE_PARTICLES, MAX_PARTICLE_ITEMS, MAX_PARTICLE_OBJECTS, MAX_PARTICLE_SIZE,
    PARTICLE_CYCLIC, PARTICLE_EMISSIONCOLOR, PARTICLE_IGNORESGRAVITY, PARTICLE_INVISIBLE, PARTICLE_ITEMCOLORS,
    PARTICLE_ITEMDENSITIES, PARTICLE_ITEMSIZES, PARTICLE_PAINTTAG, PARTICLE_PARTICLERESPONDABLE, PARTICLE_POINTS1,
    PARTICLE_POINTS2, PARTICLE_POINTS4, PARTICLE_RESPONDABLE1TO4, PARTICLE_RESPONDABLE5TO8, PARTICLE_ROUGHSPHERES,
    PARTICLE_SPHERES, PARTICLE_WATER, ParticleMaterial, ParticleObject, ParticleParams, Particles,
};
pub(crate) use physics::Physics;
pub use point_cloud::{
    DEFAULT_POINT_COLOR, MAX_INSERTION_TOLERANCE, MAX_POINT_CLOUD_POINTS, POINT_SIZE_RANGE, POINTCLOUD_EMISSIVE,
    POINTCLOUD_NO_STRUCTURE, POINTCLOUD_RANDOM_COLORS, POINTCLOUD_SHOW_OCTREE, POINTS_PER_VOXEL_RANGE, PointCloud,
    PointCloudOptions, PointColors, VOXEL_SIZE_RANGE,
};
pub use property_flags::{model_property, object_special_property};
pub use query::DistanceResult;
pub use selection::{MAX_SELECTION, Selection};
pub use shape_mesh::{MAX_MESH_TRIANGLES, ShapeMesh, decimate, geometry_mesh, mesh_data, mesh_from_lists};
pub use texture::{MAX_TEXTURE_BYTES, MAX_TEXTURE_SIDE, ShapeTexture, Texture, TextureMapping, Textures};
pub use urdf_robot::UrdfRobot;
pub use world::SceneSource;
pub use world::World;
