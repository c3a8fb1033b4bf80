//! Simulation settings: `SIM` (time step) and `DYN` (engine, gravity, engine step).

use crate::chunk::{At, Chunk, Chunks};
use crate::error::ReadError;
use crate::field::Fields;

/// The physics engine the scene was set up for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Engine {
    /// Bullet.
    Bullet,
    /// ODE.
    Ode,
    /// Vortex.
    Vortex,
    /// Newton.
    Newton,
    /// MuJoCo.
    Mujoco,
    /// A value this reader does not know.
    Other(i32),
}

/// Scene-wide settings; `None` where the file does not say.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Settings {
    /// Simulation time step, s.
    pub time_step: Option<f64>,
    /// Physics engine.
    pub engine: Option<Engine>,
    /// Gravity in the world frame, m/s².
    pub gravity: Option<[f64; 3]>,
    /// The engine's internal step, s (several per simulation step).
    pub engine_step: Option<f64>,
}

/// Reads a `SIM` chunk's stream into `settings`. The newest time-step form wins:
/// `_t3` (f64 s) over `St2` (u64 µs) over `Sts` (f32 s).
pub fn read_simulation(c: &Chunk, at: &At, settings: &mut Settings) -> Result<(), ReadError> {
    let here = at.child(c.tag, c.offset);
    let (chunks, _) = Chunks::new(c.payload, &here).part(false)?;
    let (mut sts, mut st2, mut t3) = (None, None, None);
    for c in &chunks {
        let mut f = Fields::new(c, &here);
        match &c.tag {
            b"Sts" => sts = Some(f.f32()?),
            b"St2" => st2 = Some(f.u64()? as f64 * 1e-6),
            b"_t3" => t3 = Some(f.f64()?),
            _ => {}
        }
    }
    settings.time_step = t3.or(st2).or(sts);
    Ok(())
}

/// Reads a `DYN` chunk's stream into `settings`: `Eng`/`En2`/`En3` (i32 engine, 3×f32
/// gravity) or `_n3` (i32 engine, 3×f64 gravity), and `Stp` (f32) or `_tp` (f64) step.
/// Files without a step chunk (before 4.2 or so) keep it as the first value of the
/// engine's own parameters: `Bul`/`Ode` (f32), or `BuN`/`OdN` (f32) and `_uN`/`_dN` (f64)
/// after their two counts; the one of the engine in use applies, as in CoppeliaSim.
pub fn read_dynamics(c: &Chunk, at: &At, settings: &mut Settings) -> Result<(), ReadError> {
    let here = at.child(c.tag, c.offset);
    let (chunks, _) = Chunks::new(c.payload, &here).part(false)?;
    let mut step = None;
    // First parameter (the step) of the Bullet and ODE arrays, as a fallback.
    let (mut bullet, mut ode) = (None, None);
    for c in &chunks {
        let mut f = Fields::new(c, &here);
        match &c.tag {
            b"Stp" => step = Some(f.f32()?),
            b"_tp" => step = Some(f.f64()?),
            b"Bul" => bullet = bullet.or(Some(f.f32()?)),
            b"Ode" => ode = ode.or(Some(f.f32()?)),
            b"BuN" | b"OdN" | b"_uN" | b"_dN" => {
                let floats = f.i32()?;
                let _ints = f.i32()?;
                if floats > 0 {
                    let v = if c.tag[0] == b'_' { f.f64()? } else { f.f32()? };
                    if matches!(&c.tag, b"BuN" | b"_uN") {
                        bullet = Some(v);
                    } else {
                        ode = Some(v);
                    }
                }
            }
            b"Eng" | b"En2" | b"En3" | b"_n3" => {
                settings.engine = Some(match f.i32()? {
                    0 => Engine::Bullet,
                    1 => Engine::Ode,
                    2 => Engine::Vortex,
                    3 => Engine::Newton,
                    4 => Engine::Mujoco,
                    other => Engine::Other(other),
                });
                settings.gravity = Some(f.reals::<3>(c.tag[0] == b'_')?);
            }
            _ => {}
        }
    }
    settings.engine_step = step.or(match settings.engine {
        Some(Engine::Bullet) => bullet,
        Some(Engine::Ode) => ode,
        _ => None,
    });
    Ok(())
}
