//! The confined `io` library scripts get: `io.open`, `io.lines`, `io.close`, `io.type`,
//! and `io.input`/`io.output` with `io.read`/`io.write` on files the script opened.
//!
//! Files are read from the scene's folder and the `--allow-files` folders, and written
//! (modes `w`, `a`, `+`) only in the `--allow-files` folders: CoppeliaSim scripts read
//! their own data files beside the scene, so reading there is on by default, while
//! writing is the user's choice. Relative paths are relative to the scene's folder (or,
//! for a scene embedded in gantry, to the first `--allow-files` folder); an embedded
//! scene without `--allow-files` reaches no file at all. Every path goes through
//! `crate::file_rules::confine` (symbolic links followed, and for a new file its
//! parent); a refusal raises an error naming `--allow-files`, while an ordinary failure
//! (no such file) returns `nil, message` as Lua's `io.open` does.
//!
//! Implemented in Rust over `std::fs::File` rather than by handing scripts Lua's own io
//! library behind a path check: Lua's library also carries `io.popen`, `io.tmpfile` and
//! the process's standard streams, and its files reach the C library's `FILE*`, so a
//! small library with only the parts listed here is easier to show safe. Not provided:
//! `io.popen`, `io.tmpfile` and the standard streams (scripts have no console).

use std::cell::RefCell;
use std::io::{BufRead, BufReader, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::rc::Rc;

use mlua::{AnyUserData, Lua, MultiValue, Table, UserData, UserDataMethods, Value as LuaValue, Variadic};

use crate::file_rules::{Folders, confine};

/// An open file: `None` once closed.
pub(crate) struct LuaFile(RefCell<Option<BufReader<std::fs::File>>>);

/// Puts the confined `io` table into a script's environment `env`.
///
/// # Errors
/// Out of memory.
pub(crate) fn add_io(lua: &Lua, env: &Table, folders: Rc<Folders>) -> mlua::Result<()> {
    let io = lua.create_table()?;
    let f = folders.clone();
    io.set(
        "open",
        lua.create_function(move |lua, (path, mode): (String, Option<String>)| {
            open(lua, &f, &path, mode.as_deref().unwrap_or("r"))
        })?,
    )?;
    io.set(
        "type",
        lua.create_function(|_, v: LuaValue| {
            Ok(match v.as_userdata().and_then(|u| u.borrow::<LuaFile>().ok()) {
                Some(f) if f.0.borrow().is_some() => Some("file"),
                Some(_) => Some("closed file"),
                None => None,
            })
        })?,
    )?;
    for name in ["popen", "tmpfile"] {
        io.set(
            name,
            lua.create_function(move |_, _: MultiValue| -> mlua::Result<()> {
                Err(mlua::Error::runtime(format!(
                    "io.{name} is not available in gantry scripts (the sandbox runs no programs and creates no files outside --allow-files folders)"
                )))
            })?,
        )?;
    }
    // io.lines, io.close and the default files, in Lua over `open`.
    lua.load(IO_LUA)
        .set_name("@gantry/io.lua")
        .call::<()>((io.clone(), lua.globals().get::<LuaValue>("error")?))?;
    env.set("io", io)
}

const IO_LUA: &str = r#"
local io, error = ...
local open = io.open
local input, output
function io.lines(name, ...)
    if name == nil then
        if not input then error("io.lines: no input file (open one with io.input(name))", 2) end
        return input:lines(...)
    end
    local f, e = open(name, 'r')
    if not f then error(e, 2) end
    return f:lines(...), f
end
function io.close(f)
    f = f or output
    if not f then error("io.close: no output file", 2) end
    return f:close()
end
function io.input(f)
    if type(f) == 'string' then
        local g, e = open(f, 'r')
        if not g then error(e, 2) end
        f = g
    end
    if f ~= nil then input = f end
    return input
end
function io.output(f)
    if type(f) == 'string' then
        local g, e = open(f, 'w')
        if not g then error(e, 2) end
        f = g
    end
    if f ~= nil then output = f end
    return output
end
function io.read(...)
    if not input then
        error("io.read: no input file (gantry scripts have no console; open a file with io.input(name))", 2)
    end
    return input:read(...)
end
function io.write(...)
    if not output then
        error("io.write: no output file (gantry scripts have no console; open a file with io.output(name), or use print)", 2)
    end
    return output:write(...)
end
"#;

/// `io.open(path, mode)`.
fn open(lua: &Lua, folders: &Folders, path: &str, mode: &str) -> mlua::Result<MultiValue> {
    let writes = mode.contains(['w', 'a', '+']);
    if !matches!(mode.trim_end_matches('b'), "r" | "w" | "a" | "r+" | "w+" | "a+") {
        return Err(mlua::Error::runtime(format!("io.open: invalid mode '{mode}'")));
    }
    let base: Option<&Path> = folders
        .scene
        .as_deref()
        .or(folders.writable.first().map(PathBuf::as_path));
    let Some(base) = base else {
        return Err(mlua::Error::runtime(format!(
            "io.open('{path}'): this scene has no folder on disk (it is embedded in gantry), so its scripts reach files only in folders given with --allow-files DIR"
        )));
    };
    let (roots, what) = if writes {
        (folders.writable.clone(), "write")
    } else {
        (folders.readable(), "read")
    };
    let real = confine(Path::new(path), base, &roots, what).map_err(|e| {
        let hint = if writes {
            "scripts write files only in folders given with --allow-files DIR; the scene's folder is read-only"
        } else {
            "scripts read files only in the scene's folder and in folders given with --allow-files DIR"
        };
        mlua::Error::runtime(format!("io.open: {e}: {hint}"))
    })?;
    let mut options = std::fs::OpenOptions::new();
    match mode.trim_end_matches('b') {
        "r" => options.read(true),
        "w" => options.write(true).create(true).truncate(true),
        "a" => options.append(true).create(true),
        "r+" => options.read(true).write(true),
        "w+" => options.read(true).write(true).create(true).truncate(true),
        _ => options.read(true).append(true).create(true),
    };
    match options.open(&real) {
        Ok(file) => {
            let f = lua.create_userdata(LuaFile(RefCell::new(Some(BufReader::new(file)))))?;
            Ok(MultiValue::from_iter([LuaValue::UserData(f)]))
        }
        Err(e) => Ok(MultiValue::from_iter([
            LuaValue::Nil,
            LuaValue::String(lua.create_string(format!("{path}: {e}"))?),
        ])),
    }
}

/// The error for a closed file.
fn closed() -> mlua::Error {
    mlua::Error::runtime("attempt to use a closed file")
}

/// An I/O failure as a Lua error.
fn io_err(e: std::io::Error) -> mlua::Error {
    mlua::Error::runtime(e.to_string())
}

/// Reads one value in `format` (Lua's `file:read` formats); `Nil` at the end of file.
fn read_one(lua: &Lua, r: &mut BufReader<std::fs::File>, format: &LuaValue) -> mlua::Result<LuaValue> {
    if let Some(n) = format.as_integer().or_else(|| format.as_number().map(|f| f as i64)) {
        let n = usize::try_from(n).unwrap_or(0);
        if n == 0 {
            return Ok(if r.fill_buf().map_err(io_err)?.is_empty() {
                LuaValue::Nil
            } else {
                LuaValue::String(lua.create_string("")?)
            });
        }
        let mut buf = Vec::with_capacity(n.min(1 << 16));
        r.by_ref().take(n as u64).read_to_end(&mut buf).map_err(io_err)?;
        return Ok(if buf.is_empty() {
            LuaValue::Nil
        } else {
            LuaValue::String(lua.create_string(&buf)?)
        });
    }
    let spec = match format {
        LuaValue::String(s) => s.to_string_lossy(),
        _ => return Err(mlua::Error::runtime("bad argument to 'read' (invalid format)")),
    };
    match spec.trim_start_matches('*').chars().next() {
        Some(c @ ('l' | 'L')) => {
            let mut buf = Vec::new();
            if r.read_until(b'\n', &mut buf).map_err(io_err)? == 0 {
                return Ok(LuaValue::Nil);
            }
            if c == 'l' && buf.last() == Some(&b'\n') {
                buf.pop();
            }
            Ok(LuaValue::String(lua.create_string(&buf)?))
        }
        Some('a') => {
            let mut buf = Vec::new();
            r.read_to_end(&mut buf).map_err(io_err)?;
            Ok(LuaValue::String(lua.create_string(&buf)?))
        }
        Some('n') => read_number(r),
        _ => Err(mlua::Error::runtime(format!(
            "bad argument to 'read' (invalid format '{spec}')"
        ))),
    }
}

/// `file:read('n')`: skips white space and reads a decimal number; `Nil` if none.
fn read_number(r: &mut BufReader<std::fs::File>) -> mlua::Result<LuaValue> {
    let mut text = String::new();
    loop {
        let buf = r.fill_buf().map_err(io_err)?;
        let Some(&b) = buf.first() else { break };
        let c = b as char;
        if text.is_empty() && c.is_ascii_whitespace() {
            r.consume(1);
            continue;
        }
        // Digits, signs, the point and exponents; hexadecimal is not read.
        if c.is_ascii_digit() || matches!(c, '+' | '-' | '.' | 'e' | 'E') && text.len() < 200 {
            text.push(c);
            r.consume(1);
        } else {
            break;
        }
    }
    Ok(if let Ok(i) = text.parse::<i64>() {
        LuaValue::Integer(i)
    } else if let Ok(f) = text.parse::<f64>() {
        LuaValue::Number(f)
    } else {
        LuaValue::Nil
    })
}

/// Reads `formats` (default "l") from `file`, stopping at the first `Nil` as Lua does.
fn read(lua: &Lua, file: &LuaFile, formats: &[LuaValue]) -> mlua::Result<MultiValue> {
    let mut slot = file.0.borrow_mut();
    let r = slot.as_mut().ok_or_else(closed)?;
    let default = [LuaValue::String(lua.create_string("l")?)];
    let formats = if formats.is_empty() { &default[..] } else { formats };
    let mut out = MultiValue::new();
    for f in formats {
        let v = read_one(lua, r, f)?;
        let end = v.is_nil();
        out.push_back(v);
        if end {
            break;
        }
    }
    Ok(out)
}

impl UserData for LuaFile {
    fn add_methods<M: UserDataMethods<Self>>(methods: &mut M) {
        methods.add_meta_method("__tostring", |_, this, ()| {
            Ok(if this.0.borrow().is_some() {
                "file"
            } else {
                "file (closed)"
            })
        });
        methods.add_method("read", |lua, this, formats: Variadic<LuaValue>| {
            read(lua, this, &formats)
        });
        methods.add_function("write", |_, (ud, values): (AnyUserData, Variadic<LuaValue>)| {
            {
                let this = ud.borrow::<LuaFile>()?;
                let mut slot = this.0.borrow_mut();
                let r = slot.as_mut().ok_or_else(closed)?;
                // Drop what the reader buffered, so writing starts where reading stopped.
                // (`seek` to an absolute position empties the buffer and moves the file.)
                let at = r.stream_position().map_err(io_err)?;
                r.seek(SeekFrom::Start(at)).map_err(io_err)?;
                for v in values.iter() {
                    let bytes = match v {
                        LuaValue::String(s) => s.as_bytes().to_vec(),
                        LuaValue::Integer(i) => i.to_string().into_bytes(),
                        // As Lua writes floats: "1.0", not "1".
                        LuaValue::Number(n) if n.fract() == 0.0 && n.abs() < 1e15 => format!("{n:.1}").into_bytes(),
                        LuaValue::Number(n) => n.to_string().into_bytes(),
                        other => {
                            return Err(mlua::Error::runtime(format!(
                                "bad argument to 'write' (string expected, got {})",
                                other.type_name()
                            )));
                        }
                    };
                    r.get_mut().write_all(&bytes).map_err(io_err)?;
                }
            }
            Ok(ud)
        });
        methods.add_function("lines", |lua, (ud, formats): (AnyUserData, Variadic<LuaValue>)| {
            let formats: Vec<LuaValue> = formats.into_iter().collect();
            lua.create_function(move |lua, ()| {
                let this = ud.borrow::<LuaFile>()?;
                let v = read(lua, &this, &formats)?;
                Ok(v)
            })
        });
        methods.add_method("seek", |_, this, (whence, offset): (Option<String>, Option<i64>)| {
            let mut slot = this.0.borrow_mut();
            let r = slot.as_mut().ok_or_else(closed)?;
            let offset = offset.unwrap_or(0);
            let to = match whence.as_deref().unwrap_or("cur") {
                "set" => {
                    SeekFrom::Start(u64::try_from(offset).map_err(|_| mlua::Error::runtime("seek: negative offset"))?)
                }
                "end" => SeekFrom::End(offset),
                "cur" => SeekFrom::Current(offset),
                other => {
                    return Err(mlua::Error::runtime(format!(
                        "bad argument to 'seek' (invalid option '{other}')"
                    )));
                }
            };
            r.seek(to).map_err(io_err)
        });
        methods.add_method("flush", |_, this, ()| {
            let mut slot = this.0.borrow_mut();
            slot.as_mut().ok_or_else(closed)?.get_mut().flush().map_err(io_err)?;
            Ok(true)
        });
        methods.add_method("setvbuf", |_, _, _: MultiValue| Ok(true));
        methods.add_method("close", |_, this, ()| {
            let file = this.0.borrow_mut().take().ok_or_else(closed)?;
            file.into_inner().sync_all().map_err(io_err)?;
            Ok(true)
        });
    }
}
