//! `require` of the user's own Lua modules: `require 'utils'` loads `utils.lua` (or
//! `utils/init.lua`; `a.b` is `a/b.lua`) from the scene's folder, then from each
//! `--lua-path` folder, as plain Lua source (text mode, never C modules or bytecode),
//! compiled into the environment of the script that asks, so a module runs in the same
//! sandbox and sees the same globals as its script.
//!
//! The sandbox's `require` (`crate::sandbox::add_require`) keeps the built-in modules
//! first and caches what a module returns per script, like Lua's `package.loaded`; it
//! calls [`find`] for the rest. A name with `..`, an absolute name, or a file whose real
//! path (symbolic links followed) is outside the module folders is refused.

use std::path::{Path, PathBuf};
use std::rc::Rc;

use mlua::{Function, Lua, Table};

use crate::file_rules::{Folders, confine, list};
use crate::sandbox::{REQUIRABLE, SOURCE_MODE};

/// The `find(name, env)` function the sandbox's `require` calls (see [`find`]).
///
/// # Errors
/// Out of memory.
pub(crate) fn finder(lua: &Lua, folders: Rc<Folders>) -> mlua::Result<Function> {
    lua.create_function(move |lua, (name, env): (String, Table)| {
        // A refusal goes back as a message for `require` to raise as a plain string,
        // as Lua's own `require` does, so that `pcall(require, x)` gives text.
        Ok(match find(lua, &folders, &name, env) {
            Ok((chunk, path)) => (Some(chunk), path),
            Err(mlua::Error::RuntimeError(message)) => (None, message),
            Err(mlua::Error::SyntaxError { message, .. }) => (None, message),
            Err(e) => (None, e.to_string()),
        })
    })
}

/// The module `name`'s chunk, compiled with `env` as its environment, and its file.
///
/// # Errors
/// The name is refused, no folder holds the module, the file is outside the module
/// folders, cannot be read, or does not compile.
fn find(lua: &Lua, folders: &Folders, name: &str, env: Table) -> mlua::Result<(Function, String)> {
    let roots = folders.module_roots();
    let relative = relative_path(name).map_err(mlua::Error::runtime)?;
    for root in &roots {
        for candidate in [relative.with_extension("lua"), relative.join("init.lua")] {
            let path = root.join(&candidate);
            if !path.is_file() {
                continue;
            }
            let real = confine(&candidate, root, &roots, "load modules from")
                .map_err(|e| mlua::Error::runtime(format!("module '{name}': {e}")))?;
            let source = std::fs::read(&real)
                .map_err(|e| mlua::Error::runtime(format!("module '{name}': cannot read {}: {e}", path.display())))?;
            let shown = path.display().to_string();
            let chunk = lua
                .load(source)
                .set_name(format!("@{shown}"))
                .set_mode(SOURCE_MODE)
                .set_environment(env)
                .into_function()?;
            return Ok((chunk, shown));
        }
    }
    let searched = if roots.is_empty() {
        "no folder: the scene has no folder on disk and no --lua-path was given".to_owned()
    } else {
        format!(
            "searched {} for {}.lua and {}/init.lua",
            list(&roots),
            relative.display(),
            relative.display()
        )
    };
    Err(mlua::Error::runtime(format!(
        "module '{name}' not found: it is none of gantry's modules ({}) and no file \
         provides it ({searched}; add a folder with --lua-path DIR)",
        REQUIRABLE.join(", ")
    )))
}

/// `a.b.c` as `a/b/c`, refusing names that would leave the module folders.
fn relative_path(name: &str) -> Result<PathBuf, String> {
    if name.contains("..") {
        return Err(format!(
            "module name '{name}' contains '..': modules are loaded only from inside the scene's folder and the --lua-path folders"
        ));
    }
    if name.is_empty() || Path::new(name).is_absolute() || name.starts_with(['/', '\\']) || name.contains(['\\', '\0'])
    {
        return Err(format!(
            "module name '{name}' is not a module name (an absolute path or an empty name): give a name such as 'utils' or 'lib.utils'"
        ));
    }
    let mut path = PathBuf::new();
    for part in name.split('.') {
        if part.is_empty() {
            return Err(format!("module name '{name}' has an empty part"));
        }
        path.push(part);
    }
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::relative_path;
    use std::path::PathBuf;

    #[test]
    fn names_map_to_paths_and_escapes_are_refused() {
        assert_eq!(relative_path("a.b").unwrap(), PathBuf::from("a/b"));
        assert_eq!(relative_path("utils").unwrap(), PathBuf::from("utils"));
        for bad in ["..", "../x", "a..b", "/etc/passwd", "", "a.", "a\\b"] {
            assert!(relative_path(bad).is_err(), "{bad}");
        }
    }
}
