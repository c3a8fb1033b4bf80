//! Simulation settings: `SIM` (time step), `DYN` (engine, gravity, engine step) and
//! `ENV` (the environment: background, fog and ambient light colours).

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
    /// The environment (`ENV`): colours, fog, ambient light.
    pub environment: Environment,
}

/// The scene's environment (`ENV`); `None` where the file does not say. Colours are
/// RGB, 0..1. What the fields mean was read from CoppeliaSim's published source (its
/// environment's serialization and the vision sensor's rendering); the values were
/// checked on the public files, all of which (3.6 to 4.10) hold the same: background
/// 0.804, 0.867, 0.916 up and 0.05, 0.05, 0.1 down, fog colour black, fog off, ambient
/// light 0.4 grey.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Environment {
    /// `Clc`: the top colour of the gradient CoppeliaSim's views draw behind the
    /// scene (the light grey-blue of its default scenes).
    pub background_up: Option<[f64; 3]>,
    /// `Cld`: the bottom colour of that gradient (`Clc` alone means both).
    pub background_down: Option<[f64; 3]>,
    /// `Fbg`: the fog colour. It is also the colour CoppeliaSim clears a vision
    /// sensor's image to (so what the sensor shows where it sees nothing) unless the
    /// sensor asks for a colour of its own: the colour that matters for sensors.
    pub fog_color: Option<[f64; 3]>,
    /// `Al2`: the ambient light colour (the older `Alc`, stored at half, is not read).
    pub ambient_light: Option<[f64; 3]>,
    /// Whether fog is drawn (`Var` bit 4).
    pub fog_enabled: Option<bool>,
    /// `Fd2`/`_d2`: fog type (0 linear, 1 exponential, 2 squared exponential), start
    /// distance (m) and density.
    pub fog: Option<(i32, f64, f64)>,
    /// `Fdn`/`_dn`: the fog's end distance, m.
    pub fog_end: Option<f64>,
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

/// Reads an `ENV` chunk's stream into `settings.environment`. Colours are three `f32`
/// in every version; the fog distances became `f64` (`_dn`, `_d2`) with the other
/// doubles in 4.5. Unknown chunks (textures and edges flags, job names, the scene's
/// unique id ...) are skipped.
///
/// # Errors
/// A malformed stream or a chunk too short for its values.
pub fn read_environment(c: &Chunk, at: &At, settings: &mut Settings) -> Result<(), ReadError> {
    let here = at.child(c.tag, c.offset);
    let (chunks, _) = Chunks::new(c.payload, &here).part(false)?;
    let env = &mut settings.environment;
    for c in &chunks {
        let mut f = Fields::new(c, &here);
        match &c.tag {
            b"Clc" => env.background_up = Some(f.reals::<3>(false)?),
            b"Cld" => env.background_down = Some(f.reals::<3>(false)?),
            b"Fbg" => env.fog_color = Some(f.reals::<3>(false)?),
            b"Al2" => env.ambient_light = Some(f.reals::<3>(false)?),
            b"Var" => env.fog_enabled = Some(f.u8()? & 0x10 != 0),
            b"Fdn" => env.fog_end = Some(f.f32()?),
            b"_dn" => env.fog_end = Some(f.f64()?),
            b"Fd2" | b"_d2" => {
                let double = c.tag[0] == b'_';
                let kind = f.i32()?;
                let [start, density] = f.reals::<2>(double)?;
                env.fog = Some((kind, start, density));
            }
            _ => {}
        }
    }
    // CoppeliaSim reads a lone `Clc` as both ends of the gradient.
    if env.background_down.is_none() {
        env.background_down = env.background_up;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::Stream;

    fn f32s(v: &[f32]) -> Vec<u8> {
        v.iter().flat_map(|x| x.to_le_bytes()).collect()
    }

    fn environment(stream: Stream) -> Result<Environment, ReadError> {
        let payload = stream.marker("EOO").bytes();
        let top = At::top();
        let c = Chunk {
            tag: *b"ENV",
            payload: &payload,
            offset: 0,
        };
        let mut s = Settings::default();
        read_environment(&c, &top, &mut s)?;
        Ok(s.environment)
    }

    #[test]
    fn environment_colours_fog_and_both_precisions() {
        let mut fd2 = 2i32.to_le_bytes().to_vec();
        fd2.extend(f32s(&[0.5, 0.25]));
        let env = environment(
            Stream::new()
                .chunk("Fdn", &f32s(&[7.0]))
                .chunk("Fd2", &fd2)
                .chunk("Clc", &f32s(&[0.5, 0.25, 1.0]))
                .chunk("Fbg", &f32s(&[0.125, 0.5, 0.75]))
                .chunk("Al2", &f32s(&[0.4, 0.4, 0.4]))
                .chunk("Var", &[0x18])
                .chunk("Ups", b"\x04\x00\x00\x00abcd"),
        )
        .unwrap();
        assert_eq!(env.background_up, Some([0.5, 0.25, 1.0]));
        // A lone `Clc` is both ends.
        assert_eq!(env.background_down, env.background_up);
        assert_eq!(env.fog_color, Some([0.125, 0.5, 0.75]));
        assert_eq!(env.ambient_light, Some([0.4f32, 0.4, 0.4].map(f64::from)));
        assert_eq!(
            (env.fog_enabled, env.fog, env.fog_end),
            (Some(true), Some((2, 0.5, 0.25)), Some(7.0))
        );

        let mut d2 = 1i32.to_le_bytes().to_vec();
        d2.extend([0.5f64, 2.0].iter().flat_map(|x| x.to_le_bytes()));
        let env = environment(
            Stream::new()
                .chunk("_dn", &9.0f64.to_le_bytes())
                .chunk("_d2", &d2)
                .chunk("Clc", &f32s(&[1.0, 1.0, 1.0]))
                .chunk("Cld", &f32s(&[0.0, 0.0, 0.5]))
                .chunk("Var", &[0x08]),
        )
        .unwrap();
        assert_eq!(
            (env.fog, env.fog_end, env.fog_enabled),
            (Some((1, 0.5, 2.0)), Some(9.0), Some(false))
        );
        assert_eq!(env.background_down, Some([0.0, 0.0, 0.5]));
        assert_eq!(env.fog_color, None);

        // A colour cut short is an error, not a guess.
        assert!(environment(Stream::new().chunk("Fbg", &f32s(&[1.0, 1.0]))).is_err());
    }
}
