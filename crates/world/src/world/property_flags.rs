//! The flag values of CoppeliaSim's object property functions (`sim.modelproperty_*`,
//! `sim.objectspecialproperty_*`, `sim.objectproperty_*`), apart from the world that
//! keeps them so that the physics builder can read them too.

/// Flag values of `sim.modelproperty_*`.
pub mod model_property {
    /// `sim.modelproperty_not_collidable`.
    pub const NOT_COLLIDABLE: i64 = 0x0001;
    /// `sim.modelproperty_not_measurable`.
    pub const NOT_MEASURABLE: i64 = 0x0002;
    /// `sim.modelproperty_not_renderable`.
    pub const NOT_RENDERABLE: i64 = 0x0004;
    /// `sim.modelproperty_not_detectable`.
    pub const NOT_DETECTABLE: i64 = 0x0008;
    /// `sim.modelproperty_not_cuttable` (obsolete, kept).
    pub const NOT_CUTTABLE: i64 = 0x0010;
    /// `sim.modelproperty_not_dynamic`: the model's shapes are static.
    pub const NOT_DYNAMIC: i64 = 0x0020;
    /// `sim.modelproperty_not_respondable`: the model's shapes take no part in contacts.
    pub const NOT_RESPONDABLE: i64 = 0x0040;
    /// `sim.modelproperty_not_reset`.
    pub const NOT_RESET: i64 = 0x0080;
    /// `sim.modelproperty_not_visible`.
    pub const NOT_VISIBLE: i64 = 0x0100;
    /// `sim.modelproperty_scripts_inactive`.
    pub const SCRIPTS_INACTIVE: i64 = 0x0200;
    /// `sim.modelproperty_not_showasinsidemodel`.
    pub const NOT_SHOW_AS_INSIDE_MODEL: i64 = 0x0400;
    /// `sim.modelproperty_not_model`: the object is not a model base.
    pub const NOT_MODEL: i64 = 0xf000;
    /// Every override flag (all but `NOT_MODEL`).
    pub const OVERRIDES: i64 = 0x07ff;

    /// The constants with CoppeliaSim's names, for the `sim` table.
    pub const CONSTANTS: &[(&str, i64)] = &[
        ("modelproperty_not_collidable", NOT_COLLIDABLE),
        ("modelproperty_not_measurable", NOT_MEASURABLE),
        ("modelproperty_not_renderable", NOT_RENDERABLE),
        ("modelproperty_not_detectable", NOT_DETECTABLE),
        ("modelproperty_not_cuttable", NOT_CUTTABLE),
        ("modelproperty_not_dynamic", NOT_DYNAMIC),
        ("modelproperty_not_respondable", NOT_RESPONDABLE),
        ("modelproperty_not_reset", NOT_RESET),
        ("modelproperty_not_visible", NOT_VISIBLE),
        ("modelproperty_scripts_inactive", SCRIPTS_INACTIVE),
        ("modelproperty_not_showasinsidemodel", NOT_SHOW_AS_INSIDE_MODEL),
        ("modelproperty_not_model", NOT_MODEL),
    ];
}

/// Flag values of `sim.objectspecialproperty_*` and `sim.objectproperty_*`.
pub mod object_special_property {
    /// `sim.objectspecialproperty_collidable`.
    pub const COLLIDABLE: i64 = 0x0001;
    /// `sim.objectspecialproperty_measurable`.
    pub const MEASURABLE: i64 = 0x0002;
    /// `sim.objectspecialproperty_detectable` (all five detection kinds).
    pub const DETECTABLE_ALL: i64 = 0x01f0;
    /// `sim.objectspecialproperty_renderable`.
    pub const RENDERABLE: i64 = 0x0200;
    /// What a shape starts with: collidable, measurable, detectable and renderable.
    pub const SHAPE_DEFAULT: i64 = COLLIDABLE | MEASURABLE | DETECTABLE_ALL | RENDERABLE;

    /// The constants with CoppeliaSim's names, for the `sim` table.
    pub const CONSTANTS: &[(&str, i64)] = &[
        ("objectspecialproperty_collidable", COLLIDABLE),
        ("objectspecialproperty_measurable", MEASURABLE),
        ("objectspecialproperty_detectable_ultrasonic", 0x0010),
        ("objectspecialproperty_detectable_infrared", 0x0020),
        ("objectspecialproperty_detectable_laser", 0x0040),
        ("objectspecialproperty_detectable_inductive", 0x0080),
        ("objectspecialproperty_detectable_capacitive", 0x0100),
        ("objectspecialproperty_detectable_all", DETECTABLE_ALL),
        ("objectspecialproperty_detectable", DETECTABLE_ALL),
        ("objectspecialproperty_renderable", RENDERABLE),
        ("objectspecialproperty_cuttable", 0x0400),
        ("objectspecialproperty_pathplanning_ignored", 0x0800),
        ("objectproperty_ignoreviewfitting", 0x0001),
        ("objectproperty_collapsed", 0x0010),
        ("objectproperty_selectable", 0x0020),
        ("objectproperty_selectmodelbaseinstead", 0x0080),
        ("objectproperty_dontshowasinsidemodel", 0x0100),
        ("objectproperty_selectinvisible", 0x0400),
        ("objectproperty_depthinvisible", 0x0800),
        ("objectproperty_cannotdelete", 0x1000),
        ("objectproperty_cannotdeleteduringsim", 0x2000),
        ("objectproperty_hiddenforsimulation", 0x4000),
    ];
}
