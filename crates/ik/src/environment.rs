//! The bookkeeping of `simIK`: environments, their groups and elements, and the errors of
//! looking them up. No kinematics here; see `chain` and `solver`. An environment's own
//! object tree is in `objects`.

use std::collections::BTreeMap;

use gantry_scene::Handle;

use crate::error::IkError;
use crate::objects::IkObjects;

/// How a group turns the Jacobian into joint steps (`simIK.method_*`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IkMethod {
    /// Moore-Penrose pseudo-inverse (`simIK.method_pseudo_inverse`, 0). Like CoppeliaSim,
    /// a tiny damping (1e-6) keeps it defined at singularities.
    PseudoInverse,
    /// Damped least squares `J^T (J J^T + λ² I)^-1 e` (`simIK.method_damped_least_squares`, 1).
    DampedLeastSquares,
    /// `J^T e` (`simIK.method_jacobian_transpose`, 2).
    JacobianTranspose,
    /// Pseudo-inverse with no damping at all (`simIK.method_undamped_pseudo_inverse`, 3).
    UndampedPseudoInverse,
}

impl IkMethod {
    /// The method behind CoppeliaSim's number, `None` for an unknown one.
    pub fn from_code(code: i64) -> Option<Self> {
        match code {
            0 => Some(Self::PseudoInverse),
            1 => Some(Self::DampedLeastSquares),
            2 => Some(Self::JacobianTranspose),
            3 => Some(Self::UndampedPseudoInverse),
            _ => None,
        }
    }

    /// CoppeliaSim's number for the method.
    pub fn code(self) -> i64 {
        match self {
            Self::PseudoInverse => 0,
            Self::DampedLeastSquares => 1,
            Self::JacobianTranspose => 2,
            Self::UndampedPseudoInverse => 3,
        }
    }
}

/// Which components of the tip pose an element drives onto the target
/// (`simIK.constraint_*` bits). Positions are compared in the element's base frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Constraints(pub u8);

impl Constraints {
    /// X of the position (base frame).
    pub const X: Self = Self(1);
    /// Y of the position (base frame).
    pub const Y: Self = Self(2);
    /// Z of the position (base frame).
    pub const Z: Self = Self(4);
    /// The direction of the tip's Z axis.
    pub const ALPHA_BETA: Self = Self(8);
    /// The rotation about the tip's Z axis.
    pub const GAMMA: Self = Self(16);
    /// Position only.
    pub const POSITION: Self = Self(7);
    /// Orientation only.
    pub const ORIENTATION: Self = Self(24);
    /// Position and orientation.
    pub const POSE: Self = Self(31);

    /// The constraints of a `simIK.constraint_*` combination; `None` when it has bits
    /// outside `constraint_pose` or none at all (an element with no constraint cannot
    /// be solved, so CoppeliaSim's silent "nothing to do" is reported as an error).
    pub fn from_code(code: i64) -> Option<Self> {
        if (1..=31).contains(&code) {
            u8::try_from(code).ok().map(Self)
        } else {
            None
        }
    }

    /// Whether every bit of `other` is set.
    pub fn contains(self, other: Self) -> bool {
        self.0 & other.0 == other.0
    }
}

/// Where an element's target is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ElementTarget {
    /// This object (`addElementFromScene`).
    Object(Handle),
    /// Whatever dummy the tip is linked to when the group is solved (`addElement`, whose
    /// target is set with `simIK.setLinkedDummy` or, for a scene tip, `sim.setLinkDummy`).
    LinkedDummy,
}

/// One base/tip/target triple of a group. Its objects are either scene objects or the
/// environment's own (see `objects`); a chain never crosses from one tree to the other.
#[derive(Debug, Clone, PartialEq)]
pub struct IkElement {
    /// The element's handle, unique within its environment.
    pub handle: Handle,
    /// Where the chain starts; `-1` for the world (every joint up to the root).
    pub base: Handle,
    /// The object driven onto the target.
    pub tip: Handle,
    /// The object whose pose (read at the start of each solve) the tip must reach.
    pub target: ElementTarget,
    /// What is constrained.
    pub constraints: Constraints,
    /// Success thresholds: linear (m) and angular (rad). CoppeliaSim's defaults are
    /// 0.5 mm and 0.1 deg.
    pub precision: [f64; 2],
    /// Linear and angular weights multiplying the error rows, and a weight of the element
    /// as a whole, as CoppeliaSim's `setElementWeights`. Defaults 1.
    pub weights: [f64; 3],
}

impl IkElement {
    /// CoppeliaSim's default linear precision, m.
    pub const DEFAULT_LINEAR_PRECISION: f64 = 0.0005;
    /// CoppeliaSim's default angular precision, rad (0.1 deg).
    pub const DEFAULT_ANGULAR_PRECISION: f64 = 0.1 * std::f64::consts::PI / 180.0;
}

/// A group's options (`simIK.group_*` bits, `simIK.setGroupFlags`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GroupFlags(pub u8);

impl GroupFlags {
    /// `simIK.group_enabled`: the group is solved; a disabled one is skipped.
    pub const ENABLED: Self = Self(1);
    /// `simIK.group_ignoremaxsteps`: accepted; gantry's joints have no maximum step.
    pub const IGNORE_MAX_STEPS: Self = Self(2);
    /// `simIK.group_restoreonbadlintol`: joints go back to where they were when a
    /// position constraint ends outside its precision.
    pub const RESTORE_ON_BAD_LINEAR: Self = Self(4);
    /// `simIK.group_restoreonbadangtol`: the same for orientation constraints.
    pub const RESTORE_ON_BAD_ANGULAR: Self = Self(8);
    /// CoppeliaSim's default for a new group: enabled, ignoring maximum steps.
    pub const DEFAULT: Self = Self(3);

    /// The flags of a `simIK.group_*` combination; `None` when it has bits gantry does
    /// not honour (stop on limit hit, avoid limits, ...), so a script relying on them
    /// fails instead of solving something else.
    pub fn from_code(code: i64) -> Option<Self> {
        if (0..=15).contains(&code) {
            u8::try_from(code).ok().map(Self)
        } else {
            None
        }
    }

    /// Whether every bit of `other` is set.
    pub fn contains(self, other: Self) -> bool {
        self.0 & other.0 == other.0
    }
}

/// A set of elements solved together, with its calculation settings.
#[derive(Debug, Clone, PartialEq)]
pub struct IkGroup {
    /// The group's handle, unique within its environment.
    pub handle: Handle,
    /// Optional name (`simIK.getGroupHandle`).
    pub name: String,
    /// The calculation method.
    pub method: IkMethod,
    /// Damping factor λ of damped least squares (dimensionless, applied to rows in m and rad).
    pub damping: f64,
    /// Upper bound on solver iterations per call.
    pub max_iterations: u32,
    /// Options.
    pub flags: GroupFlags,
    /// The elements in insertion order.
    pub elements: Vec<IkElement>,
}

impl IkGroup {
    /// CoppeliaSim's defaults for a new group: pseudo-inverse, damping 0.1, 3 iterations.
    fn new(handle: Handle, name: String) -> Self {
        Self {
            handle,
            name,
            method: IkMethod::PseudoInverse,
            damping: 0.1,
            max_iterations: 3,
            flags: GroupFlags::DEFAULT,
            elements: Vec::new(),
        }
    }

    /// The element behind a handle.
    ///
    /// # Errors
    /// [`IkError::NoSuchElement`].
    pub fn element_mut(&mut self, handle: Handle) -> Result<&mut IkElement, IkError> {
        let group = self.handle;
        self.elements
            .iter_mut()
            .find(|e| e.handle == handle)
            .ok_or(IkError::NoSuchElement { group, element: handle })
    }
}

/// One `simIK` environment: groups; its own object tree (dummies and joints built one
/// by one); and the joint values of solutions for scene joints computed without
/// `syncWorlds` that were not yet written to the scene (for scene objects, the scene
/// itself plays the part of CoppeliaSim's separate IK world).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct IkEnvironment {
    groups: BTreeMap<Handle, IkGroup>,
    /// The environment's own dummies and joints.
    pub objects: IkObjects,
    /// Scene joint handle → solved value (rad or m) awaiting `syncToSim`.
    pub pending: BTreeMap<Handle, f64>,
    next_handle: Handle,
}

impl IkEnvironment {
    fn allocate(&mut self) -> Handle {
        // Groups and elements share one counter, so that passing one where the other is
        // expected fails loudly instead of addressing the wrong thing.
        self.next_handle += 1;
        self.next_handle
    }

    /// Creates a group with CoppeliaSim's default settings and returns its handle.
    pub fn create_group(&mut self, name: &str) -> Handle {
        let h = self.allocate();
        self.groups.insert(h, IkGroup::new(h, name.to_owned()));
        h
    }

    /// The group behind a handle.
    ///
    /// # Errors
    /// [`IkError::NoSuchGroup`].
    pub fn group(&self, handle: Handle) -> Result<&IkGroup, IkError> {
        self.groups.get(&handle).ok_or(IkError::NoSuchGroup(handle))
    }

    /// The group behind a handle, mutably.
    ///
    /// # Errors
    /// [`IkError::NoSuchGroup`].
    pub fn group_mut(&mut self, handle: Handle) -> Result<&mut IkGroup, IkError> {
        self.groups.get_mut(&handle).ok_or(IkError::NoSuchGroup(handle))
    }

    /// The group named `name`.
    pub fn group_by_name(&self, name: &str) -> Option<Handle> {
        self.groups
            .values()
            .find(|g| !name.is_empty() && g.name == name)
            .map(|g| g.handle)
    }

    /// Adds an element (already validated) to a group and returns its handle.
    ///
    /// # Errors
    /// [`IkError::NoSuchGroup`].
    pub fn add_element(
        &mut self,
        group: Handle,
        base: Handle,
        tip: Handle,
        target: ElementTarget,
        constraints: Constraints,
    ) -> Result<Handle, IkError> {
        self.group(group)?;
        let handle = self.allocate();
        self.group_mut(group)?.elements.push(IkElement {
            handle,
            base,
            tip,
            target,
            constraints,
            precision: [
                IkElement::DEFAULT_LINEAR_PRECISION,
                IkElement::DEFAULT_ANGULAR_PRECISION,
            ],
            weights: [1.0; 3],
        });
        Ok(handle)
    }

    /// Erases one of the environment's own objects (`simIK.eraseObject`) and what refers
    /// to it, as CoppeliaSim does: elements whose tip or target it is go, elements based
    /// on it are based on the world instead.
    ///
    /// # Errors
    /// No such object.
    pub fn erase_object(&mut self, h: Handle) -> Result<(), IkError> {
        self.objects.erase(h)?;
        for g in self.groups.values_mut() {
            g.elements
                .retain(|e| e.tip != h && e.target != ElementTarget::Object(h));
            for e in &mut g.elements {
                if e.base == h {
                    e.base = -1;
                }
            }
        }
        Ok(())
    }
}

/// Every IK environment of a world, by handle (`simIK.createEnvironment`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct IkEnvironments {
    envs: BTreeMap<Handle, IkEnvironment>,
    next_handle: Handle,
}

impl IkEnvironments {
    /// Creates an empty environment and returns its handle (1, 2, ...; never reused while
    /// the world lives, so a stale handle cannot reach a newer environment).
    pub fn create(&mut self) -> Handle {
        self.next_handle += 1;
        self.envs.insert(self.next_handle, IkEnvironment::default());
        self.next_handle
    }

    /// Erases an environment with its groups and elements.
    ///
    /// # Errors
    /// [`IkError::NoSuchEnvironment`].
    pub fn erase(&mut self, handle: Handle) -> Result<(), IkError> {
        self.envs
            .remove(&handle)
            .map(|_| ())
            .ok_or(IkError::NoSuchEnvironment(handle))
    }

    /// The environment behind a handle.
    ///
    /// # Errors
    /// [`IkError::NoSuchEnvironment`].
    pub fn get(&self, handle: Handle) -> Result<&IkEnvironment, IkError> {
        self.envs.get(&handle).ok_or(IkError::NoSuchEnvironment(handle))
    }

    /// The environment behind a handle, mutably.
    ///
    /// # Errors
    /// [`IkError::NoSuchEnvironment`].
    pub fn get_mut(&mut self, handle: Handle) -> Result<&mut IkEnvironment, IkError> {
        self.envs.get_mut(&handle).ok_or(IkError::NoSuchEnvironment(handle))
    }

    /// Number of live environments.
    pub fn len(&self) -> usize {
        self.envs.len()
    }

    /// Whether no environment exists.
    pub fn is_empty(&self) -> bool {
        self.envs.is_empty()
    }
}
