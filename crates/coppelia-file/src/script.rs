//! Embedded scripts: the `LST` list at the top level and `SCT` script objects (4.7+).
//!
//! Both hold the same stream: `Si2` (id, owning object handle, type), `Va2` flags, `Ste`
//! (the text, light-encoded) and `Lne` (language, 4.7+). An `SCT` object's script
//! belongs to the object's parent.

use crate::chunk::{At, Chunk, Chunks};
use crate::error::ReadError;
use crate::field::Fields;

/// When a script runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScriptType {
    /// The scene's main script (drives the simulation loop).
    Main,
    /// A child script, run during simulation.
    Child,
    /// A customization script, run also while the simulation is stopped.
    Customization,
    /// A value this reader does not know.
    Other(i32),
}

/// The script's language.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ScriptLanguage {
    /// Lua.
    Lua,
    /// Python (4.6+).
    Python,
    /// Another language name, as stored.
    Other(String),
}

/// Where the script was stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScriptOrigin {
    /// The top-level `LST` list.
    List,
    /// The `SCT` script object with this handle.
    Object(i32),
}

/// One embedded script.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Script {
    /// Main, child or customization.
    pub script_type: ScriptType,
    /// Handle of the object it is attached to (`None` for the main script).
    pub object: Option<i32>,
    /// Where it was stored.
    pub origin: ScriptOrigin,
    /// Old-style threaded script (`Va2` bit 0).
    pub threaded: bool,
    /// Disabled (`Va2` bit 1).
    pub disabled: bool,
    /// A main script flagged as CoppeliaSim's default one (`Va2` bit 3 clear; files up
    /// to 4.1 store an empty or stale text and expect the default).
    pub default_main: bool,
    /// Lua or Python.
    pub language: ScriptLanguage,
    /// The decoded text, as written (a 4.7+ `--lua` or `#python` first line is kept).
    pub text: String,
}

/// Reads a script stream: the payload of an `LST` chunk or of an `SCT` object's `Soo`.
pub fn read(c: &Chunk, at: &At, origin: ScriptOrigin) -> Result<Script, ReadError> {
    let here = at.child(c.tag, c.offset);
    let (chunks, _) = Chunks::new(c.payload, &here).part(false)?;
    let mut s = Script {
        script_type: ScriptType::Other(-1),
        object: None,
        origin,
        threaded: false,
        disabled: false,
        default_main: false,
        language: ScriptLanguage::Lua,
        text: String::new(),
    };
    let mut va2 = None;
    let mut lne = None;
    for c in &chunks {
        let mut f = Fields::new(c, &here);
        match &c.tag {
            b"Si2" => {
                let _id = f.i32()?;
                s.object = Some(f.i32()?).filter(|&h| h >= 0);
                s.script_type = match f.i32()? {
                    0 => ScriptType::Main,
                    1 => ScriptType::Child,
                    6 => ScriptType::Customization,
                    other => ScriptType::Other(other),
                };
            }
            b"Va2" => va2 = Some(f.u8()?),
            b"Ste" => s.text = decode_text(c.payload),
            b"Lne" => lne = Some(f.string()?),
            _ => {}
        }
    }
    if let Some(bits) = va2 {
        s.threaded = bits & 0x01 != 0;
        s.disabled = bits & 0x02 != 0;
        s.default_main = s.script_type == ScriptType::Main && bits & 0x08 == 0;
    }
    s.language = match lne.as_deref() {
        Some("lua") => ScriptLanguage::Lua,
        Some("python") => ScriptLanguage::Python,
        Some(other) => ScriptLanguage::Other(other.to_owned()),
        None if s.text.starts_with("#python") => ScriptLanguage::Python,
        None => ScriptLanguage::Lua,
    };
    Ok(s)
}

/// Undoes CoppeliaSim's light encoding of script text and drops trailing NULs.
///
/// Every byte but the first and last is shifted by amounts keyed on its index and on the
/// first and last bytes (all as signed chars); those two bytes are stored as they are.
pub fn decode_text(stored: &[u8]) -> String {
    let mut b = stored.to_vec();
    let n = b.len();
    if n >= 3 {
        let start = i32::from(b[0] as i8) / 2;
        let end = i32::from(b[n - 1] as i8) * 3;
        for (i, byte) in b.iter_mut().enumerate().take(n - 1).skip(1) {
            let i = i as i32;
            let mut v = i32::from(*byte as i8);
            if i & 1 != 0 {
                v += i + start + end;
            }
            if i & 2 != 0 {
                v -= 3 * i + start;
            }
            if i & 4 != 0 {
                v += i / 2 + end;
            }
            // Wrap to a byte, as the char arithmetic it mirrors does.
            *byte = v as u8;
        }
    }
    while b.last() == Some(&0) {
        b.pop();
    }
    String::from_utf8_lossy(&b).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::light_encode;

    #[test]
    fn light_decoding_inverts_the_encoding() {
        let texts: [&[u8]; 4] = [
            b"function sysCall_init()\n    sim.addLog(sim.verbosity_msgs, 'hi')\nend\n",
            b"ab",
            b"",
            "-- ünïcode and bytes \x7f\x01 ~".as_bytes(),
        ];
        for t in texts {
            assert_eq!(decode_text(&light_encode(t)).as_bytes(), t);
        }
        // The stored form really differs from the text.
        let t = b"function f() return 1 end";
        assert_ne!(&light_encode(t)[..], &t[..]);
        // Trailing NULs go.
        assert_eq!(decode_text(&light_encode(b"x = 1\0\0")), "x = 1");
    }
}
