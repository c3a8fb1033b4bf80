//! Lights (`LGT`): omnidirectional, spot and directional light objects.
//!
//! The type-specific part, as found in CoppeliaSim 4.1 files (f32 tags) and 4.6+ files
//! (f64 tags) and as CoppeliaSim's published `light.cpp` names the fields:
//! * `Cp2`/`_p2`: i32 light type (1 omnidirectional, 2 spot, 3 directional, CoppeliaSim's
//!   `sim.light_*_subtype`), i32 spot exponent, then the size of the drawn light (f32 or
//!   f64, m; display only).
//! * `Cp3`/`_p3`: the spot cutoff angle, rad (half the cone's opening).
//! * `Caf`/`_af`: constant, linear and quadratic attenuation factors.
//! * `Cas`: u8 flags, bit 0 the light is on, bit 1 it lights only its own model
//!   ("local"). Bit 2 set meant "no POV-Ray shadow" in files before 2016; later the
//!   shadow flag lives in the extension string (see [`pov_casts_shadows`]).
//! * `Cl1`: the colour of the drawn light body (not read); `Cl2`: the light's colour, a
//!   colour object whose `Cl2`/`Cl3` hold 15 f32: ambient (reserved, written as zero by
//!   4.x), diffuse, specular, emission and auxiliary RGB triples, in that order.
//!
//! Established on the lights of PyRep's `test_scene.ttt` (4.1: a spot, an omni and a
//! directional light beside the three default directional lights) and on the 4.10
//! files of `../coppelia-files/` (the `_p2`/`_p3`/`_af` variants). The ambient slot of
//! every light seen is the legacy copy in `Cl2` and zero in `Cl3`, as 4.x's
//! `sim.getLightParameters` returns zero for it.

use crate::chunk::{At, Chunk, Chunks};
use crate::error::ReadError;
use crate::field::{Fields, is_double};

/// What kind of light (`Cp2`'s first value).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LightType {
    /// Light in every direction from a point (`sim.light_omnidirectional_subtype`, 1).
    Omnidirectional,
    /// A cone of light along the light's +Z (`sim.light_spot_subtype`, 2).
    Spot,
    /// Parallel light along the light's +Z (`sim.light_directional_subtype`, 3).
    Directional,
    /// Another value, kept as stored.
    Other(i32),
}

impl LightType {
    /// CoppeliaSim's subtype number.
    pub fn code(self) -> i32 {
        match self {
            LightType::Omnidirectional => 1,
            LightType::Spot => 2,
            LightType::Directional => 3,
            LightType::Other(c) => c,
        }
    }

    /// The type of a subtype number.
    pub fn from_code(code: i32) -> Self {
        match code {
            1 => LightType::Omnidirectional,
            2 => LightType::Spot,
            3 => LightType::Directional,
            other => LightType::Other(other),
        }
    }
}

/// A light's own part. Fields missing from the file keep CoppeliaSim's defaults for a
/// new light (on, white diffuse and specular, no attenuation but the constant one).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Light {
    /// The kind of light.
    pub light_type: LightType,
    /// On (`Cas` bit 0).
    pub on: bool,
    /// Lights only the objects of its own model (`Cas` bit 1).
    pub local: bool,
    /// Spot exponent (how the light falls off towards the cone's edge; 0 to 128).
    pub spot_exponent: i32,
    /// Spot cutoff angle, rad: the cone's half opening.
    pub spot_cutoff: f64,
    /// Constant, linear and quadratic attenuation factors.
    pub attenuation: [f64; 3],
    /// Diffuse RGB, 0..1.
    pub diffuse: [f64; 3],
    /// Specular RGB, 0..1.
    pub specular: [f64; 3],
    /// Size of the drawn light, m (display only).
    pub size: f64,
}

impl Default for Light {
    fn default() -> Self {
        Light {
            light_type: LightType::Omnidirectional,
            on: true,
            local: false,
            spot_exponent: 5,
            spot_cutoff: std::f64::consts::FRAC_PI_2,
            attenuation: [1.0, 0.0, 0.0],
            diffuse: [0.5; 3],
            specular: [0.5; 3],
            size: 0.1,
        }
    }
}

/// Reads a light's type-specific chunks.
pub fn read(chunks: &[Chunk], at: &At) -> Result<Light, ReadError> {
    let mut l = Light::default();
    for c in chunks {
        let mut f = Fields::new(c, at);
        let double = is_double(c.tag);
        match &c.tag {
            b"Cp2" | b"_p2" => {
                l.light_type = LightType::from_code(f.i32()?);
                l.spot_exponent = f.i32()?;
                [l.size] = f.reals(double)?;
            }
            b"Cp3" | b"_p3" => [l.spot_cutoff] = f.reals(double)?,
            b"Caf" | b"_af" => l.attenuation = f.reals(double)?,
            b"Cas" => {
                let flags = f.u8()?;
                l.on = flags & 1 != 0;
                l.local = flags & 2 != 0;
            }
            b"Cl2" => {
                if let Some([_, diffuse, specular]) = read_light_colour(c, at)? {
                    l.diffuse = diffuse;
                    l.specular = specular;
                }
            }
            _ => {}
        }
    }
    Ok(l)
}

/// The ambient, diffuse and specular triples of a colour object (the last of its
/// `Cl2`/`Cl3` chunks), if it has one.
fn read_light_colour(c: &Chunk, at: &At) -> Result<Option<[[f64; 3]; 3]>, ReadError> {
    let here = at.child(c.tag, c.offset);
    let (chunks, _) = Chunks::new(c.payload, &here).part(false)?;
    let mut out = None;
    for c in chunks.iter().filter(|c| matches!(&c.tag, b"Cl2" | b"Cl3")) {
        let v: [f64; 9] = Fields::new(c, &here).reals(false)?;
        out = Some([[v[0], v[1], v[2]], [v[3], v[4], v[5]], [v[6], v[7], v[8]]]);
    }
    Ok(out)
}

/// Whether a light's extension string says it casts POV-Ray shadows
/// (`sim.lightintparam_pov_casts_shadows`): the value of `povray {shadow {...}}` is
/// `true`. CoppeliaSim keeps the flag there since 2016 (`povray {shadow {true}
/// fadeXDist {0.00}} openGL3 {...}` in the lights of 4.1 scenes); absent means no.
pub fn pov_casts_shadows(extension: &str) -> bool {
    extension_value(extension, &["povray", "shadow"]).is_some_and(|v| v == "true")
}

/// The value at `path` in CoppeliaSim's extension-string syntax, `key {value} key2
/// {nested {value}}`, trimmed; `None` when the path is absent or the text malformed.
/// The recursion is as deep as `path` is long.
pub fn extension_value<'a>(text: &'a str, path: &[&str]) -> Option<&'a str> {
    let (first, rest) = path.split_first()?;
    let mut s = text;
    loop {
        s = s.trim_start();
        if s.is_empty() {
            return None;
        }
        let key_end = s.find(|c: char| c.is_whitespace() || c == '{' || c == '}')?;
        let key = &s[..key_end];
        let after = s[key_end..].trim_start();
        let body_start = after.strip_prefix('{')?;
        // The matching brace.
        let mut depth = 1usize;
        let mut end = None;
        for (i, ch) in body_start.char_indices() {
            match ch {
                '{' => depth += 1,
                '}' => {
                    depth -= 1;
                    if depth == 0 {
                        end = Some(i);
                        break;
                    }
                }
                _ => {}
            }
        }
        let end = end?;
        let body = &body_start[..end];
        if key == *first {
            return if rest.is_empty() {
                Some(body.trim())
            } else {
                extension_value(body, rest)
            };
        }
        s = &body_start[end + 1..];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extension_values_are_found_by_path() {
        let ext = "povray {shadow {true} fadeXDist {0.00}} openGL3 {lightProjection {nearPlane {0.1}}}";
        assert_eq!(extension_value(ext, &["povray", "shadow"]), Some("true"));
        assert_eq!(extension_value(ext, &["povray", "fadeXDist"]), Some("0.00"));
        assert_eq!(
            extension_value(ext, &["openGL3", "lightProjection", "nearPlane"]),
            Some("0.1")
        );
        assert_eq!(extension_value(ext, &["shadow"]), None);
        assert!(pov_casts_shadows(ext));
        assert!(!pov_casts_shadows("povray {shadow {false}}"));
        assert!(!pov_casts_shadows(""));
        // Malformed text is absent, never a panic.
        for bad in [
            "povray {shadow {true}",
            "povray",
            "{",
            "}",
            "a {b} c",
            "povray {shadow {tr}ue}}}",
        ] {
            let _ = extension_value(bad, &["povray", "shadow"]);
        }
    }
}
