//! Two files are generated from the registry, with the notes on differences from
//! CoppeliaSim kept in `docs/api-notes.md`: `docs/api.md` (every function scripts and
//! remote clients can call, where each may be called, and every constant) and
//! `python/gantry/_api.pyi` (the Python package's type stubs, so that editors complete
//! `sim.` calls).
//!
//! The tests fail when a file and the registry disagree. To regenerate after adding a
//! function: `GANTRY_BLESS=1 cargo test --test integration api_doc::`.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;

use gantry_sim_core::api::MODULES;
use gantry_sim_core::api::{ApiFn, HOST_FUNCTIONS, HOST_MODULES, InScripts, Remote, Touches};
use gantry_test_support::repo;

/// What one row says.
struct Row {
    scripts: &'static str,
    remote: &'static str,
    touches: &'static str,
    notes: Vec<String>,
}

/// Notes by qualified name, from lines "- `sim.name`: text" of docs/api-notes.md.
fn notes(text: &str) -> BTreeMap<String, Vec<String>> {
    let mut out: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for line in text.lines() {
        let Some(rest) = line.strip_prefix("- `") else { continue };
        let Some((name, note)) = rest.split_once("`: ") else {
            continue;
        };
        out.entry(name.to_owned()).or_default().push(note.trim().to_owned());
    }
    out
}

fn generate(notes_text: &str) -> (String, Vec<String>) {
    let mut notes = notes(notes_text);
    let mut out = String::new();
    let mut functions = 0;
    let mut constants = 0;
    let mut modules = String::new();
    for module in MODULES {
        let mut rows: BTreeMap<String, Row> = BTreeMap::new();
        for (name, f) in module.callable() {
            let mut row = Row {
                scripts: "yes",
                remote: "yes",
                touches: match f.call {
                    ApiFn::World(_) => "world",
                    ApiFn::Sim(_) => "simulation",
                },
                notes: Vec::new(),
            };
            if f.name != name {
                row.notes
                    .push(format!("CoppeliaSim 4.0-4.5 name of `{}.{}`.", module.name, f.name));
            }
            rows.insert(name.to_owned(), row);
        }
        if module.name == "sim" {
            for h in HOST_FUNCTIONS {
                let scripts = match h.scripts {
                    InScripts::No => "no",
                    InScripts::AnyHook => "yes",
                    InScripts::ThreadedOnly => "threaded scripts",
                };
                let remote = if h.remote == Remote::No { "no" } else { "yes" };
                let touches = touches_name(h.touches);
                rows.insert(
                    h.name.to_owned(),
                    Row {
                        scripts,
                        remote,
                        touches,
                        notes: Vec::new(),
                    },
                );
            }
        }
        let _ = writeln!(modules, "\n## {}\n", module.name);
        let _ = writeln!(modules, "| Function | Scripts | Remote clients | Touches | Notes |");
        let _ = writeln!(modules, "|---|---|---|---|---|");
        for (name, mut row) in rows {
            let qualified = format!("{}.{name}", module.name);
            row.notes.extend(notes.remove(&qualified).unwrap_or_default());
            let _ = writeln!(
                modules,
                "| `{qualified}` | {} | {} | {} | {} |",
                row.scripts,
                row.remote,
                row.touches,
                row.notes.join(" ").replace('|', "\\|")
            );
            functions += 1;
        }
        let mut consts: Vec<(&str, i64)> = module.constants.iter().map(|(n, v)| (*n, *v)).collect();
        if !consts.is_empty() {
            consts.sort_unstable();
            let _ = writeln!(modules, "\nConstants of `{}`:\n", module.name);
            let list: Vec<String> = consts.iter().map(|(n, v)| format!("`{n}` = {v}")).collect();
            let _ = writeln!(modules, "{}", list.join(", "));
            constants += consts.len();
        }
    }
    for module in HOST_MODULES {
        let _ = writeln!(modules, "\n## {}\n", module.name);
        let _ = writeln!(modules, "| Function | Scripts | Remote clients | Touches | Notes |");
        let _ = writeln!(modules, "|---|---|---|---|---|");
        for h in module.functions {
            let qualified = format!("{}.{}", module.name, h.name);
            let row_notes = notes.remove(&qualified).unwrap_or_default();
            let scripts = if h.scripts == InScripts::No { "no" } else { "yes" };
            let remote = if h.remote == Remote::No { "no" } else { "yes" };
            let _ = writeln!(
                modules,
                "| `{qualified}` | {scripts} | {remote} | {} | {} |",
                touches_name(h.touches),
                row_notes.join(" ").replace('|', "\\|")
            );
            functions += 1;
        }
    }
    let _ = writeln!(
        out,
        "# The gantry API\n\n\
         Every function gantry's Lua scripts and remote clients (ZMQ remote API, Python) can call, \
         and every constant: {functions} functions in {} modules, {constants} constants. \
         Generated from the registry by `GANTRY_BLESS=1 cargo test --test integration api_doc::`; the test fails \
         when this file and the code disagree. Differences from CoppeliaSim are noted per function \
         (kept in `docs/api-notes.md`).\n\n\
         \"Scripts\" is where a Lua script may call it (\"threaded scripts\": only from \
         `sysCall_thread`, `sysCall_threadmain` or a coroutine, because it blocks). \"Remote \
         clients\" is whether the ZMQ remote API serves it. \"Touches\" is what the \
         function may act on: the world (objects and physics), the simulation (also its \
         state, signals, drawings, graphs, UIs, IK and vision), the simulation loop \
         (starting, stepping, locks), the scripts, the scene as a whole, or the world through \
         a motion over several steps, or the front end's listeners (see docs/architecture.md). \
         Units are SI and angles radians, as in CoppeliaSim.",
        MODULES.len() + HOST_MODULES.len()
    );
    out.push_str(&modules);
    let unknown = notes.into_keys().collect();
    (out, unknown)
}

#[test]
fn api_reference_matches_the_registry() {
    let notes_text = std::fs::read_to_string(repo("docs/api-notes.md")).expect("docs/api-notes.md");
    let (generated, unknown) = generate(&notes_text);
    assert!(
        unknown.is_empty(),
        "docs/api-notes.md has notes for functions that do not exist: {unknown:?}"
    );
    let path = repo("docs/api.md");
    if std::env::var_os("GANTRY_BLESS").is_some() {
        std::fs::write(&path, &generated).expect("write docs/api.md");
        return;
    }
    let current = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        current == generated,
        "docs/api.md is out of date with the registry: run `GANTRY_BLESS=1 cargo test --test integration api_doc::`"
    );
}

/// How docs/api.md names what a host function touches.
fn touches_name(t: Touches) -> &'static str {
    match t {
        Touches::Loop => "loop",
        Touches::Scripts => "scripts",
        Touches::Scene => "scene",
        Touches::Motion => "motion",
        Touches::Listeners => "listeners",
        Touches::Ros => "the ROS 2 network",
        Touches::Programs => "programs",
    }
}

/// The class name of a module's stub: `sim` → `Sim`, `simIK` → `SimIK`.
fn class_name(module: &str) -> String {
    let mut c = module.chars();
    c.next()
        .map(|f| f.to_ascii_uppercase().to_string() + c.as_str())
        .unwrap_or_default()
}

/// `python/gantry/_api.pyi`: one class per module that `gantry.Client.require`
/// returns, every function and constant the Python client can call, each function's
/// notes as its docstring.
fn generate_stubs(notes_text: &str) -> String {
    let notes = notes(notes_text);
    let mut out = String::from(
        "# The gantry API for Python type checkers and editors: one class per module that\n\
         # `gantry.Client.require` returns, every function and constant of the registry.\n\
         # Generated by `GANTRY_BLESS=1 cargo test --test integration api_doc::`; do not edit.\n\
         # Arguments and results are CoppeliaSim's (docs/api.md); units SI, angles radians.\n\n\
         from typing import Any\n",
    );
    for module in MODULES {
        let mut names: BTreeSet<&str> = module.callable().map(|(n, _)| n).collect();
        if module.name == "sim" {
            names.extend(HOST_FUNCTIONS.iter().filter(|h| h.remote != Remote::No).map(|h| h.name));
        }
        let _ = writeln!(out, "\nclass {}:", class_name(module.name));
        let _ = writeln!(
            out,
            "    \"\"\"`{}`: {} functions, {} constants.\"\"\"\n",
            module.name,
            names.len(),
            module.constants.iter().count()
        );
        // A dotted constant (`StateSpaceType.pose3d`) is a member of a nested namespace.
        let mut constants: Vec<String> = module
            .constants
            .iter()
            .map(|(n, _)| match n.split_once('.') {
                Some((group, _)) => format!("{group}: Any"),
                None => format!("{n}: int"),
            })
            .collect();
        constants.sort_unstable();
        constants.dedup();
        for c in constants {
            let _ = writeln!(out, "    {c}");
        }
        if module.name == "sim" {
            // Added on the client's side, as CoppeliaSim's remote client does.
            out.push_str("    def getScriptFunctions(self, scriptHandle: int) -> Any: ...\n");
            out.push_str("    def copyTable(self, table: Any) -> Any: ...\n");
        }
        for name in names {
            let qualified = format!("{}.{name}", module.name);
            match notes.get(&qualified) {
                Some(lines) => {
                    let doc = lines.join(" ").replace('\\', "\\\\").replace("\"\"\"", "'''");
                    let _ = writeln!(
                        out,
                        "    def {name}(self, *args: Any) -> Any:\n        \"\"\"{doc}\"\"\""
                    );
                }
                None => {
                    let _ = writeln!(out, "    def {name}(self, *args: Any) -> Any: ...");
                }
            }
        }
    }
    out
}

#[test]
fn python_stubs_match_the_registry() {
    let notes_text = std::fs::read_to_string(repo("docs/api-notes.md")).expect("docs/api-notes.md");
    let generated = generate_stubs(&notes_text);
    let path = repo("python/gantry/_api.pyi");
    if std::env::var_os("GANTRY_BLESS").is_some() {
        std::fs::write(&path, &generated).expect("write python/gantry/_api.pyi");
        return;
    }
    let current = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        current == generated,
        "python/gantry/_api.pyi is out of date with the registry: run `GANTRY_BLESS=1 cargo test --test integration api_doc::`"
    );
}
