//! The rewrites CoppeliaSim applies to old scripts when it loads an old file, so that
//! scripts written for V-REP 3.x run on the 4.x API:
//!
//! - **flat names**: the 3.x API was flat globals; 4.0 moved it into namespaces. A call
//!   `simGetObjectHandle(` becomes `sim.getObjectHandle(`, a constant
//!   `sim_handle_parent` becomes `sim.handle_parent`. Plugin namespaces that already
//!   look like `simXxx` (`simUI`, `simIK`, `simVision`, ...) are used with a dot, never
//!   called, so only a name followed by `(` is renamed; a few 3.x plugin entry points
//!   have their 4.x homes (`simExtRemoteApiStart(` is `simRemoteApi.start(`).
//! - **call types**: a 3.0-3.2 non-threaded child script is one chunk that CoppeliaSim
//!   ran at every pass with the global `sim_call_type` saying which
//!   (`sim_childscriptcall_initialization`, ...). It becomes the chunk inside a
//!   function, called from `sysCall_init`/`_actuation`/`_sensing`/`_cleanup` with
//!   `sim_call_type` set, which is what the old host did.
//! - **old threads**: a 3.x threaded child script is top-level code run once in its own
//!   thread. It becomes the body of `sysCall_thread`, unless it already defines one
//!   (4.0-4.2 scripts define `sysCall_threadmain`, which gantry runs as is).
//!
//! The rewrite reads the script as Lua tokens, so strings and comments are left alone.
//! It is pure and total: any text in, text out.

/// 3.x plugin entry points whose 4.x names are not the flat-name rule's.
const SPECIAL: &[(&str, &str)] = &[
    ("simExtRemoteApiStart", "simRemoteApi.start"),
    ("simExtRemoteApiStop", "simRemoteApi.stop"),
    ("simExtRemoteApiStatus", "simRemoteApi.status"),
];

/// The 3.x call-type globals, kept as globals (the wrapper sets them) rather than renamed.
const CALL_TYPES: &[(&str, i64)] = &[
    ("sim_childscriptcall_initialization", 0),
    ("sim_childscriptcall_actuation", 1),
    ("sim_childscriptcall_sensing", 2),
    ("sim_childscriptcall_cleanup", 3),
];

/// What [`modernize`] changed, for the import report.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Rewrites {
    /// Flat names renamed (call sites and constants).
    pub renamed: usize,
    /// The script was a 3.0-3.2 `sim_call_type` chunk and is now wrapped in hooks.
    pub call_types: bool,
    /// The script was a 3.x threaded script and is now the body of `sysCall_thread`.
    pub thread_body: bool,
}

impl Rewrites {
    /// Whether anything changed.
    pub fn any(&self) -> bool {
        self.renamed > 0 || self.call_types || self.thread_body
    }
}

/// Rewrites an old script as CoppeliaSim does on load (see the module comment).
/// `threaded` is the file's old threaded-script flag.
pub fn modernize(text: &str, threaded: bool) -> (String, Rewrites) {
    let mut rewrites = Rewrites::default();
    let mut out = String::with_capacity(text.len() + 64);
    let bytes = text.as_bytes();
    let mut i = 0;
    let mut uses_call_type = false;
    let mut defines_thread = false;
    while i < bytes.len() {
        let c = bytes[i];
        if let Some(end) = skip_string_or_comment(bytes, i) {
            out.push_str(&text[i..end]);
            i = end;
            continue;
        }
        if c.is_ascii_alphabetic() || c == b'_' {
            let start = i;
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                i += 1;
            }
            let word = &text[start..i];
            // A field or method (`a.simFoo`, `a:simFoo`), not the `..` concatenation.
            let after_dot = start > 0
                && (bytes[start - 1] == b':' || (bytes[start - 1] == b'.' && (start < 2 || bytes[start - 2] != b'.')));
            let called = text[i..].trim_start_matches([' ', '\t']).starts_with('(');
            match rename(word, called, after_dot) {
                Some(new) => {
                    out.push_str(&new);
                    rewrites.renamed += 1;
                }
                None => out.push_str(word),
            }
            uses_call_type |= word == "sim_call_type" && !after_dot;
            defines_thread |= matches!(word, "sysCall_thread" | "sysCall_threadmain");
            continue;
        }
        // Not an identifier start: copy one character (UTF-8 safe).
        let ch = text[i..].chars().next().unwrap_or('\u{fffd}');
        out.push(ch);
        i += ch.len_utf8().max(1);
    }
    if uses_call_type && !threaded {
        out = wrap_call_types(&out);
        rewrites.call_types = true;
    } else if threaded && !defines_thread {
        out = format!("function sysCall_thread()\n{out}\nend\n");
        rewrites.thread_body = true;
    }
    (out, rewrites)
}

/// The 4.x spelling of a 3.x flat name, if `word` is one.
fn rename(word: &str, called: bool, after_dot: bool) -> Option<String> {
    if after_dot {
        return None;
    }
    if let Some((_, new)) = SPECIAL.iter().find(|(old, _)| *old == word) {
        return called.then(|| (*new).to_owned());
    }
    if let Some(rest) = word.strip_prefix("sim_") {
        // Constants: lower-case words after the prefix. The call-type globals stay.
        let constant = rest.starts_with(|c: char| c.is_ascii_lowercase()) && word != "sim_call_type";
        let call_type = CALL_TYPES.iter().any(|(n, _)| *n == word);
        return (constant && !call_type).then(|| format!("sim.{rest}"));
    }
    let rest = word.strip_prefix("sim")?;
    let mut chars = rest.chars();
    let first = chars.next()?;
    let second = chars.next()?;
    // `simGetObjectHandle`: a capital then a small letter; `simUI`, `simIK`, `simROS`
    // (two capitals) and any name that is not called are namespaces, left alone.
    if !(called && first.is_ascii_uppercase() && second.is_ascii_lowercase()) || rest.starts_with("Ext") {
        return None;
    }
    Some(format!(
        "sim.{}{}",
        first.to_ascii_lowercase(),
        &rest[first.len_utf8()..]
    ))
}

/// A 3.0-3.2 call-type chunk inside the 4.x hooks.
fn wrap_call_types(body: &str) -> String {
    let mut out = String::from("-- gantry: a V-REP 3.0-3.2 script, run at each pass with sim_call_type set\n");
    for (name, value) in CALL_TYPES {
        out.push_str(&format!("{name}={value}\n"));
    }
    out.push_str("local function __pass()\n");
    out.push_str(body);
    out.push_str("\nend\n");
    for (hook, name) in [
        ("sysCall_init", "sim_childscriptcall_initialization"),
        ("sysCall_actuation", "sim_childscriptcall_actuation"),
        ("sysCall_sensing", "sim_childscriptcall_sensing"),
        ("sysCall_cleanup", "sim_childscriptcall_cleanup"),
    ] {
        out.push_str(&format!("function {hook}() sim_call_type={name} __pass() end\n"));
    }
    out
}

/// The end of the string or comment starting at `i`, if one does.
fn skip_string_or_comment(b: &[u8], i: usize) -> Option<usize> {
    match b[i] {
        b'-' if b.get(i + 1) == Some(&b'-') => {
            if let Some(end) = long_bracket(b, i + 2) {
                return Some(end);
            }
            let nl = b[i..].iter().position(|&c| c == b'\n').map_or(b.len(), |p| i + p);
            Some(nl)
        }
        b'"' | b'\'' => {
            let quote = b[i];
            let mut j = i + 1;
            while j < b.len() {
                match b[j] {
                    b'\\' => j += 2,
                    c if c == quote || c == b'\n' => return Some(j + 1),
                    _ => j += 1,
                }
            }
            Some(b.len())
        }
        b'[' => long_bracket(b, i),
        _ => None,
    }
}

/// The end of a long bracket `[[...]]` or `[==[...]==]` opening at `i`, if one does.
fn long_bracket(b: &[u8], i: usize) -> Option<usize> {
    if b.get(i) != Some(&b'[') {
        return None;
    }
    let level = b[i + 1..].iter().take_while(|&&c| c == b'=').count();
    if b.get(i + 1 + level) != Some(&b'[') {
        return None;
    }
    let close: Vec<u8> = std::iter::once(b']')
        .chain(std::iter::repeat_n(b'=', level))
        .chain(std::iter::once(b']'))
        .collect();
    let from = i + 2 + level;
    Some(
        b[from..]
            .windows(close.len())
            .position(|w| w == close.as_slice())
            .map_or(b.len(), |p| from + p + close.len()),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_calls_and_constants_take_their_namespaced_names() {
        let old = "h=simGetObjectHandle('arm')\nsimSetJointTargetVelocity(h, 1)\np=simGetObjectPosition(h,sim_handle_parent)\n\
                   print('n '..simGetObjectName(h))\n";
        let (new, r) = modernize(old, false);
        assert_eq!(
            new,
            "h=sim.getObjectHandle('arm')\nsim.setJointTargetVelocity(h, 1)\np=sim.getObjectPosition(h,sim.handle_parent)\n\
             print('n '..sim.getObjectName(h))\n"
        );
        assert_eq!(r.renamed, 5);
        assert!(!r.call_types && !r.thread_body);
    }

    #[test]
    fn namespaces_strings_comments_and_new_scripts_are_left_alone() {
        let text = "local ui=simUI.create(x)\nsimIK.handleGroup(e,g)\nsimVision.sensorImgToWorkImg(h)\n\
                    print('simGetObjectHandle(') -- simGetObjectHandle(\n--[[ simSetJointPosition(h,0) ]]\n\
                    s=[==[sim_handle_all]==]\nsim.getObject('/a')\nlocal simple=1\nmySimFoo(2)\n";
        let (new, r) = modernize(text, false);
        assert_eq!(new, text);
        assert!(!r.any());
    }

    #[test]
    fn old_plugin_entry_points_move_to_their_namespaces() {
        let (new, _) = modernize("simExtRemoteApiStart(19999)\n", false);
        assert_eq!(new, "simRemoteApi.start(19999)\n");
    }

    #[test]
    fn a_call_type_chunk_becomes_hooks_that_set_sim_call_type() {
        let old = "if (sim_call_type==sim_childscriptcall_initialization) then\n  h=simGetObjectHandle('a')\nend\n";
        let (new, r) = modernize(old, false);
        assert!(r.call_types && r.renamed == 1);
        assert!(
            new.contains("sim_call_type==sim_childscriptcall_initialization"),
            "{new}"
        );
        assert!(new.contains("function sysCall_init() sim_call_type=sim_childscriptcall_initialization __pass() end"));
        assert!(new.contains("function sysCall_cleanup()"));
        assert!(new.contains("sim_childscriptcall_initialization=0"));
    }

    #[test]
    fn an_old_threaded_script_becomes_the_thread_body() {
        let (new, r) = modernize("while true do simSwitchThread() end\n", true);
        assert!(r.thread_body);
        assert_eq!(
            new,
            "function sysCall_thread()\nwhile true do sim.switchThread() end\n\nend\n"
        );
        // A 4.0-4.2 threaded script already names its body.
        let (same, r) = modernize("function sysCall_threadmain() end\n", true);
        assert!(!r.any());
        assert_eq!(same, "function sysCall_threadmain() end\n");
    }

    #[test]
    fn any_text_is_accepted() {
        for text in [
            "",
            "[",
            "[==",
            "--[[",
            "'unterminated",
            "sim",
            "sim_",
            "simA(",
            "é simÉ(",
            "\"\\",
        ] {
            let _ = modernize(text, false);
            let _ = modernize(text, true);
        }
    }
}
