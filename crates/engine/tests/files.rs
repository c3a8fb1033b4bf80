//! Files for scripts, confined (issue 49): `io.open` reads the scene's folder and the
//! `--allow-files` folders and writes only in the latter; everything else, a symbolic
//! link out of a folder included, is refused with a message naming `--allow-files`, and
//! a scene embedded in gantry reaches no file without it.

use crate::util;

use gantry_lua::ScriptLimits;
use gantry_sim_core::Value;
use gantry_test_support::{TempDir, assert_contains, load, text};
use util::{Drive, LUA_ERR, PROBE_ONLY_SCENE, Scene, assert_running};

/// The probe scene with `source` (plus `err`) as `probe.lua` and `files` beside it,
/// started.
fn scene(tag: &str, source: &str, files: &[(&str, &str)], limits: ScriptLimits) -> Scene {
    let source = format!("{source}\n{LUA_ERR}");
    let mut all = vec![("probe.lua", source.as_str())];
    all.extend_from_slice(files);
    let mut sc = Scene::new(tag, PROBE_ONLY_SCENE, &all, limits);
    sc.sim.start();
    sc
}

fn s(v: &str) -> Value {
    Value::Str(v.to_owned())
}

fn allowing(dir: &TempDir) -> ScriptLimits {
    ScriptLimits {
        allow_files: vec![dir.path().to_owned()],
        ..ScriptLimits::default()
    }
}

/// Writes a CSV into `dir` (a path given by the test) and reads it back three ways.
const CSV_PROBE: &str = r#"
function write_csv(path)
    local f = assert(io.open(path, 'w'))
    f:write('t,x\n')
    for i = 1, 3 do f:write(i, ',', i * 0.5, '\n') end
    assert(f:close())
    local a = assert(io.open(path, 'a'))
    a:write('4,2.0\n')
    a:close()
end
function read_csv(path)
    local rows = {}
    for line in io.lines(path) do rows[#rows + 1] = line end
    local f = assert(io.open(path))
    local header = f:read('l')
    local t, comma, x = f:read('n', 1, 'n')
    local size = f:seek('end')
    f:close()
    return table.concat(rows, ';'), header, t, x, size, io.type(f)
end
function refused(path, mode) return err(function() return io.open(path, mode) end) end
"#;

#[test]
fn a_script_writes_a_csv_in_an_allowed_folder_and_reads_it_back() {
    let data = TempDir::new("files-allowed");
    let mut sc = scene("files-csv", CSV_PROBE, &[], allowing(&data));
    let path = data.path().join("log.csv").display().to_string();
    sc.call("write_csv", &[s(&path)]);
    let out = sc.call("read_csv", &[s(&path)]);
    assert_eq!(
        out,
        vec![
            s("t,x;1,0.5;2,1.0;3,1.5;4,2.0"),
            s("t,x"),
            Value::Int(1),
            Value::Float(0.5),
            Value::Int(28),
            s("closed file")
        ]
    );
    assert_eq!(
        std::fs::read_to_string(data.path().join("log.csv")).expect("written"),
        "t,x\n1,0.5\n2,1.0\n3,1.5\n4,2.0\n"
    );
    assert_running(&sc.sim, "probe.lua");
}

#[test]
fn the_scenes_folder_is_readable_by_relative_path_but_not_writable() {
    let mut sc = scene(
        "files-scene",
        &format!("{CSV_PROBE}\nfunction data() return io.open('table.txt'):read('a') end"),
        &[("table.txt", "1 2 3")],
        ScriptLimits::default(),
    );
    assert_eq!(sc.call("data", &[]), vec![s("1 2 3")]);
    for mode in ["w", "a", "r+"] {
        let msg = text(&sc.call("refused", &[s("table.txt"), s(mode)])[0]).to_owned();
        assert_contains(
            &msg,
            &["outside the folders scripts may write", "--allow-files", "read-only"],
        );
    }
    assert_eq!(
        std::fs::read_to_string(sc.dir.path().join("table.txt")).expect("kept"),
        "1 2 3"
    );
}

#[test]
fn writing_outside_the_allowed_folders_is_refused_and_writes_nothing() {
    let data = TempDir::new("files-allowed-2");
    let elsewhere = TempDir::new("files-elsewhere");
    let mut sc = scene("files-outside", CSV_PROBE, &[], allowing(&data));
    let outside = elsewhere.path().join("x.csv");
    let climbing = data.path().join("../x.csv");
    for path in [&outside, &climbing] {
        let msg = text(&sc.call("refused", &[s(&path.display().to_string()), s("w")])[0]).to_owned();
        assert_contains(&msg, &["outside the folders scripts may write", "--allow-files"]);
    }
    assert!(!outside.exists(), "a script wrote {}", outside.display());
    let msg = text(&sc.call("refused", &[s(&outside.display().to_string()), s("r")])[0]).to_owned();
    assert_contains(&msg, &["outside the folders scripts may read", "--allow-files"]);
}

#[cfg(unix)]
#[test]
fn a_symlink_out_of_an_allowed_folder_is_refused_for_reading_and_writing() {
    let data = TempDir::new("files-link");
    let elsewhere = TempDir::new("files-link-target");
    let secret = elsewhere.write("secret.txt", "secret");
    std::os::unix::fs::symlink(&secret, data.path().join("link.txt")).expect("symlink");
    std::os::unix::fs::symlink(elsewhere.path(), data.path().join("out")).expect("symlink");
    // A dangling link: creating the file would follow it out.
    let dangling = elsewhere.path().join("created.txt");
    std::os::unix::fs::symlink(&dangling, data.path().join("dangling.txt")).expect("symlink");
    let mut sc = scene("files-link-scene", CSV_PROBE, &[], allowing(&data));
    let at = |name: &str| data.path().join(name).display().to_string();
    for (name, mode) in [
        ("link.txt", "r"),
        ("link.txt", "w"),
        ("out/new.txt", "w"),
        ("dangling.txt", "w"),
    ] {
        let msg = text(&sc.call("refused", &[s(&at(name)), s(mode)])[0]).to_owned();
        assert_contains(&msg, &["outside the folders scripts may", "--allow-files"]);
    }
    assert_eq!(std::fs::read_to_string(&secret).expect("kept"), "secret");
    assert!(!dangling.exists() && !elsewhere.path().join("new.txt").exists());
}

#[test]
fn popen_and_the_console_are_refused() {
    let mut sc = scene(
        "files-popen",
        "function probe() return err(io.popen, 'id'), err(io.read), err(io.write, 'x') end",
        &[],
        ScriptLimits::default(),
    );
    let out = sc.call("probe", &[]);
    assert_contains(text(&out[0]), &["io.popen is not available"]);
    assert_contains(text(&out[1]), &["io.read: no input file"]);
    assert_contains(text(&out[2]), &["io.write: no output file"]);
}

#[test]
fn an_embedded_scene_reaches_no_file() {
    let dir = TempDir::new("files-embedded");
    dir.write("data.txt", "x");
    dir.write(
        "probe.lua",
        format!("function probe() return err(io.open, 'data.txt') end\n{LUA_ERR}"),
    );
    let mut model = load(&dir.write("scene.toml", PROBE_ONLY_SCENE));
    // What the loader gives the scene compiled into the binary.
    model.base_dir = "/embedded/assets/scenes".into();
    let mut sim = util::engine(model, ScriptLimits::default()).expect("builds");
    sim.start();
    let msg = text(&util::call(&mut sim, "probe", &[])[0]).to_owned();
    assert_contains(&msg, &["no folder on disk", "--allow-files"]);
}
