//! `simUI` through the API: the BubbleRob seed's UI, values, events, warnings, errors
//! and limits.

use crate::util;

use gantry_sim_core::api::{self, CallContext};
use gantry_sim_core::ui::{Layout, MAX_UIS, MAX_WIDGETS, MAX_XML_LEN, Placement, UiEvent, WidgetKind};
use gantry_sim_core::{Handle, Sim, Value};

fn world() -> Sim {
    util::asset_scene("scenes/bubble_rob.toml")
}

fn base(w: &Sim) -> Handle {
    w.world.find("/bubbleRob", None, 0).expect("/bubbleRob")
}

/// The context of BubbleRob's child script.
fn script(obj: Handle) -> CallContext<'static> {
    CallContext {
        script_object: Some(obj),
        source: "bubbleRob.lua",
    }
}

fn call(w: &mut Sim, ctx: &CallContext<'_>, name: &str, args: &[Value]) -> Result<Vec<Value>, String> {
    api::call(w, ctx, name, args).map_err(|e| e.to_string())
}

fn int(v: &[Value]) -> i64 {
    v.first().and_then(Value::as_i64).expect("an integer result")
}

/// The seed controller's XML exactly as its script builds it (one line before the long
/// string, as in the real script), with the alias `sim.getObjectAlias(base, 1)` returns.
fn seed_xml(alias: &str) -> String {
    format!(
        "<ui title=\"{alias} speed\" closeable=\"false\" resizeable=\"false\" activate=\"false\">\n\
         <hslider minimum=\"0\" maximum=\"100\" onchange=\"speedChange_callback\" id=\"1\"/>\n        \
         <label text=\"\" style=\"* {{margin-left: 300px;}}\"/>\n        </ui>\n        "
    )
}

/// Creates the seed UI from BubbleRob's script; returns the world, the script context and the handle.
fn seed_ui() -> (Sim, CallContext<'static>, i64) {
    let mut w = world();
    let ctx = script(base(&w));
    let obj = Value::Int(base(&w));
    let alias = call(&mut w, &ctx, "sim.getObjectAlias", &[obj, Value::Int(1)]).expect("alias");
    let alias = alias[0].as_str().expect("text").to_owned();
    let ui = int(&call(&mut w, &ctx, "simUI.create", &[Value::from(seed_xml(&alias))]).expect("create"));
    (w, ctx, ui)
}

fn warnings(w: &Sim) -> Vec<String> {
    w.world
        .log
        .lines()
        .filter(|l| l.verbosity == 300)
        .map(|l| l.message.clone())
        .collect()
}

#[test]
fn seed_xml_creates_a_slider_0_to_100() {
    let (w, ctx, ui) = seed_ui();
    let window = w.uis.get(ui).expect("the ui exists");
    assert_eq!(window.title, "/bubbleRob speed");
    assert!(!window.closeable && !window.activate && window.visible);
    assert_eq!(window.owner, ctx.script_object);
    assert_eq!(window.content.layout, Layout::VBox);

    let WidgetKind::Slider(s) = &window.widget(1).expect("widget 1").kind else {
        panic!("widget 1 is not a slider");
    };
    assert_eq!((s.minimum, s.maximum, s.value), (0, 100, 0));
    assert_eq!(s.on_change.as_deref(), Some("speedChange_callback"));

    // The label has no id: simUI gives it a negative one.
    let widgets = window.widgets();
    assert_eq!(widgets.len(), 2);
    assert!(widgets[1].id < 0);
    assert!(matches!(&widgets[1].kind, WidgetKind::Label(l) if l.text.is_empty()));
    assert_eq!(widgets[1].style, "* {margin-left: 300px;}");
}

#[test]
fn seed_xml_creates_its_ui_without_a_warning() {
    // CoppeliaSim runs the tutorial's UI without complaint: `resizeable` is its
    // spelling of `resizable`, and the old `onchange` is only a deprecation note.
    let (w, _, ui) = seed_ui();
    assert_eq!(warnings(&w), Vec::<String>::new());
    assert!(!w.uis.get(ui).expect("the UI").resizable);
    let notes = lines_at(&w, 450);
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert!(
        notes[0].contains("'onchange' is deprecated. please use 'on-change'"),
        "{notes:?}"
    );
    assert!(w.world.log.lines().all(|l| l.source == "bubbleRob.lua"));

    // The attribute is read: `resizeable="true"` makes a resizable window.
    let mut w = world();
    let ctx = script(base(&w));
    let xml = "<ui title=\"t\" resizeable=\"true\"><label text=\"x\"/></ui>";
    let h = int(&call(&mut w, &ctx, "simUI.create", &[Value::from(xml)]).expect("create"));
    assert!(w.uis.get(h).expect("the UI").resizable);
    assert_eq!(warnings(&w), Vec::<String>::new());
}

/// Log lines at one verbosity.
fn lines_at(w: &Sim, verbosity: i64) -> Vec<String> {
    w.world
        .log
        .lines()
        .filter(|l| l.verbosity == verbosity)
        .map(|l| l.message.clone())
        .collect()
}

#[test]
fn deprecated_spelling_is_reported_once_per_world() {
    let (mut w, ctx, _) = seed_ui();
    let alias = "/bubbleRob";
    call(&mut w, &ctx, "simUI.create", &[Value::from(seed_xml(alias))]).expect("create");
    let deprecated = lines_at(&w, 450).iter().filter(|m| m.contains("deprecated")).count();
    assert_eq!(deprecated, 1);
}

#[test]
fn slider_values_round_and_clamp_without_events_by_default() {
    let (mut w, ctx, ui) = seed_ui();
    let get = |w: &mut Sim| int(&call(w, &ctx, "simUI.getSliderValue", &[Value::Int(ui), Value::Int(1)]).expect("get"));
    // The seed's 100*(speed-min)/(max-min), which is 50 give or take a rounding error.
    let (min, max) = (50f64.to_radians(), 300f64.to_radians());
    let v = 100.0 * ((min + max) * 0.5 - min) / (max - min);
    call(
        &mut w,
        &ctx,
        "simUI.setSliderValue",
        &[Value::Int(ui), Value::Int(1), Value::Float(v)],
    )
    .expect("set");
    assert_eq!(get(&mut w), 50);
    for (set, expect) in [(150, 100), (-5, 0), (73, 73)] {
        call(
            &mut w,
            &ctx,
            "simUI.setSliderValue",
            &[Value::Int(ui), Value::Int(1), Value::Int(set)],
        )
        .expect("set");
        assert_eq!(get(&mut w), expect);
    }
    assert!(w.uis.take_events().is_empty(), "suppressEvents defaults to true");
}

#[test]
fn interact_queues_exactly_one_callback_event() {
    let (mut w, ctx, ui) = seed_ui();
    call(
        &mut w,
        &ctx,
        "simUI.interact",
        &[Value::Int(ui), Value::Int(1), Value::Int(80)],
    )
    .expect("interact");
    assert_eq!(
        w.uis.take_events(),
        vec![UiEvent {
            ui,
            widget: 1,
            callback: "speedChange_callback".into(),
            value: Value::Int(80),
            script_object: ctx.script_object,
        }]
    );
    assert!(w.uis.take_events().is_empty(), "taking empties the queue");
    assert_eq!(w.uis.slider_value(ui, 1), Ok(80));

    // Moving it to where it is emits nothing, as Qt's valueChanged.
    call(
        &mut w,
        &ctx,
        "simUI.interact",
        &[Value::Int(ui), Value::Int(1), Value::Int(80)],
    )
    .expect("interact");
    assert!(w.uis.take_events().is_empty());
}

#[test]
fn suppress_events_false_queues_the_callback_on_change_only() {
    let (mut w, ctx, ui) = seed_ui();
    let set = |w: &mut Sim, v: i64, suppress: Value| {
        call(
            w,
            &ctx,
            "simUI.setSliderValue",
            &[Value::Int(ui), Value::Int(1), Value::Int(v), suppress],
        )
        .expect("set");
    };
    set(&mut w, 20, Value::Bool(false));
    let events = w.uis.take_events();
    assert_eq!(events.len(), 1);
    assert_eq!((events[0].widget, &events[0].value), (1, &Value::Int(20)));
    set(&mut w, 20, Value::Bool(false));
    assert!(w.uis.take_events().is_empty(), "no change, no event");
    set(&mut w, 30, Value::Bool(true));
    set(&mut w, 40, Value::Nil);
    assert!(w.uis.take_events().is_empty());
}

#[test]
fn unknown_attributes_warn_but_create_the_ui() {
    let mut w = world();
    let ctx = script(base(&w));
    let xml = r#"<ui><button id="3" text="Go" colour="red" on-click="go"/></ui>"#;
    let ui = int(&call(&mut w, &ctx, "simUI.create", &[Value::from(xml)]).expect("create"));
    assert!(
        warnings(&w).contains(&"simUI: unknown UI XML attribute 'colour' in widget 'button'".to_owned()),
        "{:?}",
        warnings(&w)
    );
    call(&mut w, &ctx, "simUI.interact", &[Value::Int(ui), Value::Int(3)]).expect("click");
    let events = w.uis.take_events();
    assert_eq!(events.len(), 1);
    assert_eq!((events[0].callback.as_str(), &events[0].value), ("go", &Value::Nil));
}

#[test]
fn malformed_xml_is_an_error_with_line_and_column() {
    let mut w = world();
    let ctx = script(base(&w));
    let err = call(
        &mut w,
        &ctx,
        "simUI.create",
        &[Value::from("<ui>\n  <hslider id=\"1\">\n</ui>")],
    )
    .expect_err("mismatched tag");
    assert!(err.starts_with("invalid UI XML at line 3, column"), "{err}");
    assert!(err.ends_with("(in function 'simUI.create')"), "{err}");

    let err = call(&mut w, &ctx, "simUI.create", &[Value::from("<ui title=\"x></ui>")]).expect_err("open quote");
    assert!(err.contains("line 1, column"), "{err}");
    assert!(w.uis.is_empty());
}

#[test]
fn invalid_ui_descriptions_name_the_element_and_its_position() {
    let mut w = world();
    let ctx = script(base(&w));
    for (xml, expect) in [
        (
            "<ui>\n<hslider id=\"0\"/></ui>",
            "hslider at line 2, column 1: id must be a positive integer",
        ),
        (
            "<ui><label id=\"2\"/><edit id=\"2\"/></ui>",
            "edit[id=2] at line 1, column 20: id must be unique",
        ),
        ("<ui><hslider id=\"1\" inverted=\"yes\"/></ui>", "must be true or false"),
        (
            "<ui><hslider id=\"1\" maximum=\"ten\"/></ui>",
            "invalid value 'ten' for attribute 'maximum'",
        ),
        (
            "<ui layout=\"circle\"/>",
            "invalid value for attribute 'layout': 'circle'",
        ),
        ("<ui><blink/></ui>", "invalid element <blink>"),
        ("<ui><combobox id=\"4\"/></ui>", "<combobox> is not supported by gantry"),
        (
            "<ui layout=\"grid\"><stretch/></ui>",
            "stretch must be placed in a widget with vbox/hbox layout",
        ),
        (
            "<ui layout=\"form\"><label/><edit/><label/></ui>",
            "extra elements in layout",
        ),
        (
            "<ui><button geometry=\"0,0,10,10\"/></ui>",
            "cannot set geometry with current layout",
        ),
        ("<dialog/>", "root element must be <ui>"),
    ] {
        let err = call(&mut w, &ctx, "simUI.create", &[Value::from(xml)]).expect_err(xml);
        assert!(err.contains(expect), "{xml}: {err}");
    }
    assert!(w.uis.is_empty());
}

#[test]
fn destroy_invalidates_the_handle_and_drops_its_events() {
    let (mut w, ctx, ui) = seed_ui();
    call(
        &mut w,
        &ctx,
        "simUI.interact",
        &[Value::Int(ui), Value::Int(1), Value::Int(5)],
    )
    .expect("interact");
    call(&mut w, &ctx, "simUI.destroy", &[Value::Int(ui)]).expect("destroy");
    assert!(w.uis.is_empty());
    assert!(w.uis.take_events().is_empty(), "no callback for a destroyed UI");
    let err = call(&mut w, &ctx, "simUI.getSliderValue", &[Value::Int(ui), Value::Int(1)]).expect_err("gone");
    assert_eq!(
        err,
        format!("invalid ui handle: {ui} (in function 'simUI.getSliderValue')")
    );
    let err = call(&mut w, &ctx, "simUI.destroy", &[Value::Int(ui)]).expect_err("twice");
    assert!(err.ends_with("(in function 'simUI.destroy')"), "{err}");

    // Handles are not reused.
    let again = int(&call(&mut w, &ctx, "simUI.create", &[Value::from(seed_xml("/x"))]).expect("create"));
    assert_ne!(again, ui);
}

#[test]
fn bad_handles_ids_types_and_arguments_name_the_function() {
    let (mut w, ctx, ui) = seed_ui();
    let label = w.uis.get(ui).expect("ui").widgets()[1].id;
    for (name, args, expect) in [
        (
            "simUI.getSliderValue",
            vec![Value::Int(4242), Value::Int(1)],
            "invalid ui handle: 4242",
        ),
        (
            "simUI.getSliderValue",
            vec![Value::Int(ui), Value::Int(7)],
            "invalid widget id: 7",
        ),
        (
            "simUI.getSliderValue",
            vec![Value::Int(ui), Value::Int(label)],
            "invalid widget type. expected slider",
        ),
        (
            "simUI.setLabelText",
            vec![Value::Int(ui), Value::Int(1), Value::from("x")],
            "invalid widget type. expected label",
        ),
        (
            "simUI.getSliderValue",
            vec![Value::from("ui"), Value::Int(1)],
            "argument 1: expected integer, got string",
        ),
        (
            "simUI.setSliderValue",
            vec![Value::Int(ui), Value::Int(1), Value::Float(f64::NAN)],
            "argument 3: expected a finite number",
        ),
        (
            "simUI.setSliderValue",
            vec![Value::Int(ui), Value::Int(1), Value::Int(3), Value::from("no")],
            "argument 4: expected boolean",
        ),
        (
            "simUI.create",
            vec![Value::Int(3)],
            "argument 1: expected string, got number",
        ),
        (
            "simUI.interact",
            vec![Value::Int(ui), Value::Int(1), Value::from("fast")],
            "a slider takes a finite number, got string",
        ),
        (
            "simUI.setCheckboxValue",
            vec![Value::Int(ui), Value::Int(1), Value::Int(2)],
            "invalid widget type. expected checkbox",
        ),
    ] {
        let err = call(&mut w, &ctx, name, &args).expect_err(name);
        assert!(err.starts_with(expect), "{name}: {err}");
        assert!(err.ends_with(&format!("(in function '{name}')")), "{err}");
    }
}

const PANEL: &str = r#"
<ui title="Panel" closeable="true" layout="vbox">
  <group id="10" text="Drive" layout="form">
    <label id="11" text="Name"/>
    <edit id="12" value="rover" on-change="nameChanged" on-editing-finished="nameDone"/>
    <label id="13" text="Gain"/>
    <spinbox id="14" minimum="0" maximum="2" step="0.1" value="1" on-change="gain"/>
  </group>
  <group id="20" layout="grid" flat="true">
    <checkbox id="21" text="Trace" checked="true" on-change="trace"/>
    <radiobutton id="22" text="A" checked="true" on-click="pickA"/>
    <br/>
    <radiobutton id="23" text="B" on-click="pickB"/>
    <vslider id="24" minimum="-10" maximum="10" value="50"/>
  </group>
  <label id="30" text="&lt;a href='help'&gt;help&lt;/a&gt;" on-link-activated="link"/>
  <stretch factor="2"/>
  <button id="40" text="Toggle" checkable="true" on-click="toggled"/>
</ui>"#;

#[test]
fn a_panel_of_every_widget_reads_and_reacts() {
    let mut w = world();
    let ctx = script(base(&w));
    let ui = int(&call(&mut w, &ctx, "simUI.create", &[Value::from(PANEL)]).expect("create"));
    assert!(warnings(&w).is_empty(), "{:?}", warnings(&w));

    // The layout tree the viewer reads.
    let window = w.uis.get(ui).expect("ui");
    let rows = &window.content.rows;
    assert_eq!(rows.len(), 5, "group, group, label, stretch, button: one per vbox row");
    let WidgetKind::Group(form) = &rows[0][0].kind else {
        panic!("group")
    };
    assert_eq!(form.content.layout, Layout::Form);
    assert_eq!(form.content.rows.iter().map(Vec::len).collect::<Vec<_>>(), [2, 2]);
    let WidgetKind::Group(grid) = &rows[1][0].kind else {
        panic!("group")
    };
    assert_eq!(grid.content.rows.iter().map(Vec::len).collect::<Vec<_>>(), [2, 2]);
    assert!(grid.flat);
    assert!(matches!(&rows[3][0].kind, WidgetKind::Stretch(s) if s.factor == 2));
    let WidgetKind::Slider(v) = &window.widget(24).expect("vslider").kind else {
        panic!("slider")
    };
    assert_eq!(
        (v.minimum, v.maximum, v.value),
        (-10, 10, 10),
        "value clamped at creation"
    );
    assert_eq!(window.widgets().len(), 13);

    let i = |w: &mut Sim, id: i64, v: Value| {
        call(w, &ctx, "simUI.interact", &[Value::Int(ui), Value::Int(id), v]).expect("interact");
    };
    let names = |w: &mut Sim| -> Vec<(String, Value)> {
        w.uis.take_events().into_iter().map(|e| (e.callback, e.value)).collect()
    };

    // Edit: typing then Enter.
    i(&mut w, 12, Value::from("bubble"));
    assert_eq!(
        names(&mut w),
        [
            ("nameChanged".into(), Value::from("bubble")),
            ("nameDone".into(), Value::from("bubble"))
        ]
    );
    call(
        &mut w,
        &ctx,
        "simUI.setEditValue",
        &[Value::Int(ui), Value::Int(12), Value::from("r2"), Value::Bool(false)],
    )
    .expect("set");
    assert_eq!(names(&mut w), [("nameChanged".into(), Value::from("r2"))]);
    let got = call(&mut w, &ctx, "simUI.getEditValue", &[Value::Int(ui), Value::Int(12)]).expect("get");
    assert_eq!(got, [Value::from("r2")]);

    // Float spin box: clamped, float events.
    i(&mut w, 14, Value::Float(7.5));
    assert_eq!(names(&mut w), [("gain".into(), Value::Float(2.0))]);

    // Checkbox: nil toggles, 0/2 states.
    i(&mut w, 21, Value::Nil);
    assert_eq!(names(&mut w), [("trace".into(), Value::Int(0))]);
    call(
        &mut w,
        &ctx,
        "simUI.setCheckboxValue",
        &[Value::Int(ui), Value::Int(21), Value::Int(2)],
    )
    .expect("set");
    let got = call(
        &mut w,
        &ctx,
        "simUI.getCheckboxValue",
        &[Value::Int(ui), Value::Int(21)],
    )
    .expect("get");
    assert_eq!(got, [Value::Int(2)]);
    let err = call(
        &mut w,
        &ctx,
        "simUI.setCheckboxValue",
        &[Value::Int(ui), Value::Int(21), Value::Int(3)],
    )
    .expect_err("3");
    assert!(err.starts_with("invalid checkbox value: must be 0, 1 or 2"), "{err}");

    // Radio buttons are exclusive within their group.
    i(&mut w, 23, Value::Nil);
    assert_eq!(names(&mut w), [("pickB".into(), Value::Nil)]);
    assert_eq!(w.uis.radiobutton_value(ui, 22), Ok(false));
    assert_eq!(w.uis.radiobutton_value(ui, 23), Ok(true));

    // Label link, checkable button.
    i(&mut w, 30, Value::from("help"));
    assert_eq!(names(&mut w), [("link".into(), Value::from("help"))]);
    i(&mut w, 40, Value::Nil);
    assert_eq!(names(&mut w), [("toggled".into(), Value::Nil)]);
    assert!(matches!(&w.uis.widget(ui, 40).expect("button").kind, WidgetKind::Button(b) if b.checked));

    // setLabelText / getLabelText.
    call(
        &mut w,
        &ctx,
        "simUI.setLabelText",
        &[Value::Int(ui), Value::Int(11), Value::from("Alias")],
    )
    .expect("set");
    let got = call(&mut w, &ctx, "simUI.getLabelText", &[Value::Int(ui), Value::Int(11)]).expect("get");
    assert_eq!(got, [Value::from("Alias")]);
    assert!(names(&mut w).is_empty());

    // A group and a stretch take no input.
    let err = call(&mut w, &ctx, "simUI.interact", &[Value::Int(ui), Value::Int(10)]).expect_err("group");
    assert!(err.contains("takes no input"), "{err}");
}

#[test]
fn disabled_widgets_and_groups_refuse_the_user_not_the_script() {
    let mut w = world();
    let ctx = script(base(&w));
    let ui = int(&call(&mut w, &ctx, "simUI.create", &[Value::from(PANEL)]).expect("create"));
    call(
        &mut w,
        &ctx,
        "simUI.setEnabled",
        &[Value::Int(ui), Value::Int(20), Value::Bool(false)],
    )
    .expect("disable");
    let got = call(&mut w, &ctx, "simUI.getEnabled", &[Value::Int(ui), Value::Int(20)]).expect("get");
    assert_eq!(got, [Value::Bool(false)]);
    let err = call(&mut w, &ctx, "simUI.interact", &[Value::Int(ui), Value::Int(21)]).expect_err("inside");
    assert!(err.starts_with("widget 21 is disabled"), "{err}");
    // Scripts may still set values.
    call(
        &mut w,
        &ctx,
        "simUI.setCheckboxValue",
        &[Value::Int(ui), Value::Int(21), Value::Int(0)],
    )
    .expect("set");
}

#[test]
fn closing_hides_or_asks_the_script() {
    let mut w = world();
    let ctx = script(base(&w));
    let (seed, panel) = (
        int(&call(&mut w, &ctx, "simUI.create", &[Value::from(seed_xml("/b"))]).expect("create")),
        int(&call(&mut w, &ctx, "simUI.create", &[Value::from(PANEL)]).expect("create")),
    );
    let err = call(&mut w, &ctx, "simUI.interact", &[Value::Int(seed), Value::Int(0)]).expect_err("not closeable");
    assert!(err.contains("is not closeable"), "{err}");

    call(&mut w, &ctx, "simUI.interact", &[Value::Int(panel), Value::Int(0)]).expect("close");
    let got = call(&mut w, &ctx, "simUI.isVisible", &[Value::Int(panel)]).expect("visible");
    assert_eq!(got, [Value::Bool(false)]);
    let err = call(&mut w, &ctx, "simUI.interact", &[Value::Int(panel), Value::Int(40)]).expect_err("hidden");
    assert!(err.contains("is hidden"), "{err}");
    call(&mut w, &ctx, "simUI.show", &[Value::Int(panel)]).expect("show");
    assert_eq!(w.uis.is_visible(panel), Ok(true));

    let xml = r#"<ui closeable="true" on-close="closing"><label/></ui>"#;
    let asks = int(&call(&mut w, &ctx, "simUI.create", &[Value::from(xml)]).expect("create"));
    call(&mut w, &ctx, "simUI.interact", &[Value::Int(asks), Value::Int(0)]).expect("close");
    let events = w.uis.take_events();
    assert_eq!(events.len(), 1);
    assert_eq!(
        (events[0].ui, events[0].widget, events[0].callback.as_str()),
        (asks, 0, "closing")
    );
    assert_eq!(w.uis.is_visible(asks), Ok(true), "with on-close the script decides");
}

#[test]
fn remote_clients_own_no_script() {
    let mut w = world();
    let ctx = CallContext {
        script_object: None,
        source: "remote",
    };
    let ui = int(&call(&mut w, &ctx, "simUI.create", &[Value::from(seed_xml("/r"))]).expect("create"));
    call(
        &mut w,
        &ctx,
        "simUI.interact",
        &[Value::Int(ui), Value::Int(1), Value::Int(9)],
    )
    .expect("interact");
    assert_eq!(w.uis.take_events()[0].script_object, None);
}

#[test]
fn destroy_owned_by_removes_only_that_scripts_uis() {
    let (mut w, ctx, ui) = seed_ui();
    let other = CallContext {
        script_object: Some(-77),
        source: "other.lua",
    };
    let kept = int(&call(&mut w, &other, "simUI.create", &[Value::from(seed_xml("/o"))]).expect("create"));
    assert_eq!(w.uis.destroy_owned_by(ctx.script_object.expect("obj")), 1);
    assert!(w.uis.get(ui).is_none());
    assert!(w.uis.get(kept).is_some());
}

#[test]
fn limits_are_enforced() {
    let mut w = world();
    let ctx = script(base(&w));
    let long = format!("<ui><label text=\"{}\"/></ui>", "x".repeat(MAX_XML_LEN));
    let err = call(&mut w, &ctx, "simUI.create", &[Value::from(long)]).expect_err("long");
    assert!(err.starts_with("UI XML too long"), "{err}");

    let many = format!("<ui>{}</ui>", "<label/>".repeat(MAX_WIDGETS + 1));
    let err = call(&mut w, &ctx, "simUI.create", &[Value::from(many)]).expect_err("many");
    assert!(err.contains("too many widgets"), "{err}");

    let deep = format!("<ui>{}{}</ui>", "<group>".repeat(40), "</group>".repeat(40));
    let err = call(&mut w, &ctx, "simUI.create", &[Value::from(deep)]).expect_err("deep");
    assert!(err.contains("nested too deeply"), "{err}");

    for _ in 0..MAX_UIS {
        call(&mut w, &ctx, "simUI.create", &[Value::from("<ui/>")]).expect("create");
    }
    let err = call(&mut w, &ctx, "simUI.create", &[Value::from("<ui/>")]).expect_err("full");
    assert!(err.starts_with("too many UIs"), "{err}");

    let ui = w.uis.iter().next().expect("one").handle;
    let text = "y".repeat(MAX_XML_LEN + 1);
    call(&mut w, &ctx, "simUI.destroy", &[Value::Int(ui)]).expect("destroy");
    let ui = int(&call(
        &mut w,
        &ctx,
        "simUI.create",
        &[Value::from("<ui><label id=\"1\"/></ui>")],
    )
    .expect("create"));
    let err = call(
        &mut w,
        &ctx,
        "simUI.setLabelText",
        &[Value::Int(ui), Value::Int(1), Value::from(text)],
    )
    .expect_err("long text");
    assert!(err.starts_with("text too long"), "{err}");
}

#[test]
fn no_input_prefix_panics() {
    // Every prefix of a rich document, and some hostile ones, must give Ok or Err.
    let mut w = world();
    let ctx = script(base(&w));
    let hostile = [
        "",
        "<",
        "<?xml version=\"1.0\"?><!DOCTYPE ui [<!ENTITY a \"aaaa\">]><ui>&a;</ui>",
        "<ui><hslider minimum=\"2147483648\"/></ui>",
        "<ui><hslider minimum=\"100\" maximum=\"0\" value=\"-5\"/></ui>",
        "<ui position=\"1,2,3\" size=\",\"/>",
        "<ui><spinbox minimum=\"1e309\"/></ui>",
        "<ui><label id=\"99999999999\"/></ui>",
    ];
    let mut inputs: Vec<&str> = hostile.to_vec();
    inputs.extend(PANEL.char_indices().map(|(i, _)| &PANEL[..i]));
    for xml in inputs {
        if let Ok(ret) = call(&mut w, &ctx, "simUI.create", &[Value::from(xml)]) {
            call(&mut w, &ctx, "simUI.destroy", &[ret[0].clone()]).expect("destroy");
        }
    }
    // minimum > maximum collapses the range like Qt.
    let ui = int(&call(
        &mut w,
        &ctx,
        "simUI.create",
        &[Value::from(
            "<ui><hslider id=\"1\" minimum=\"100\" maximum=\"0\"/></ui>",
        )],
    )
    .expect("create"));
    assert_eq!(w.uis.slider_value(ui, 1), Ok(0));
}

/// A window with a button (1) and a slider (2), created by BubbleRob's script.
fn window_ui() -> (Sim, CallContext<'static>, i64) {
    let mut w = world();
    let ctx = script(base(&w));
    let xml = "<ui title=\"Panel\" placement=\"center\" position=\"10,20\">\
               <button id=\"1\" text=\"Go\" on-click=\"go\"/>\
               <hslider id=\"2\" minimum=\"0\" maximum=\"10\" on-change=\"moved\"/></ui>";
    let ui = int(&call(&mut w, &ctx, "simUI.create", &[Value::from(xml)]).expect("create"));
    (w, ctx, ui)
}

#[test]
fn position_and_title_read_back_and_move_the_window() {
    let (mut w, ctx, ui) = window_ui();
    let h = Value::Int(ui);
    let pos = call(&mut w, &ctx, "simUI.getPosition", std::slice::from_ref(&h)).expect("get");
    assert_eq!(pos, vec![Value::Int(10), Value::Int(20)]);
    let rev = w.uis.revision();
    call(
        &mut w,
        &ctx,
        "simUI.setPosition",
        &[h.clone(), Value::Int(300), Value::Int(-40)],
    )
    .expect("set");
    assert!(w.uis.revision() != rev, "the viewer sees the change");
    let pos = call(&mut w, &ctx, "simUI.getPosition", std::slice::from_ref(&h)).expect("get");
    assert_eq!(pos, vec![Value::Int(300), Value::Int(-40)]);
    // Qt moves the window to screen coordinates, whatever the XML's placement.
    assert_eq!(w.uis.get(ui).expect("ui").placement, Placement::Absolute);
    call(
        &mut w,
        &ctx,
        "simUI.setPosition",
        &[h.clone(), Value::Int(1), Value::Int(2), Value::Bool(false)],
    )
    .expect("suppressEvents accepted");

    let title = call(&mut w, &ctx, "simUI.getTitle", std::slice::from_ref(&h)).expect("title");
    assert_eq!(title, vec![Value::from("Panel")]);
    call(&mut w, &ctx, "simUI.setTitle", &[h.clone(), Value::from("Renamed")]).expect("set title");
    assert_eq!(w.uis.get(ui).expect("ui").title, "Renamed");
    assert_eq!(
        call(&mut w, &ctx, "simUI.getTitle", &[h]).expect("title"),
        vec![Value::from("Renamed")]
    );
    assert!(w.uis.take_events().is_empty(), "no callback for moves or titles");
}

#[test]
fn hidden_widgets_and_button_text() {
    let (mut w, ctx, ui) = window_ui();
    let h = Value::Int(ui);
    let visible = |w: &mut Sim, id: i64| {
        call(w, &ctx, "simUI.getWidgetVisibility", &[Value::Int(ui), Value::Int(id)]).expect("get")
    };
    assert_eq!(visible(&mut w, 1), vec![Value::Bool(true)]);
    call(
        &mut w,
        &ctx,
        "simUI.setWidgetVisibility",
        &[h.clone(), Value::Int(1), Value::Bool(false)],
    )
    .expect("hide");
    assert_eq!(visible(&mut w, 1), vec![Value::Bool(false)]);
    assert!(!w.uis.widget(ui, 1).expect("widget").visible);
    // A user cannot click what is hidden.
    assert!(call(&mut w, &ctx, "simUI.interact", &[h.clone(), Value::Int(1), Value::Nil]).is_err());
    call(
        &mut w,
        &ctx,
        "simUI.setWidgetVisibility",
        &[h.clone(), Value::Int(1), Value::Bool(true)],
    )
    .expect("show");
    call(&mut w, &ctx, "simUI.interact", &[h.clone(), Value::Int(1), Value::Nil]).expect("click");
    assert_eq!(w.uis.take_events().len(), 1);

    call(
        &mut w,
        &ctx,
        "simUI.setButtonText",
        &[h.clone(), Value::Int(1), Value::from("Stop")],
    )
    .expect("text");
    let WidgetKind::Button(b) = &w.uis.widget(ui, 1).expect("widget").kind else {
        panic!("widget 1 is a button");
    };
    assert_eq!(b.text, "Stop");
    assert!(w.uis.take_events().is_empty(), "a text change clicks nothing");
}

#[test]
fn window_and_widget_setters_check_handles_ids_and_types() {
    let (mut w, ctx, ui) = window_ui();
    let h = Value::Int(ui);
    for (name, args, expect) in [
        ("simUI.getPosition", vec![Value::Int(4242)], "invalid ui handle: 4242"),
        (
            "simUI.setPosition",
            vec![Value::Int(4242), Value::Int(0), Value::Int(0)],
            "invalid ui handle: 4242",
        ),
        ("simUI.getTitle", vec![Value::Int(4242)], "invalid ui handle: 4242"),
        (
            "simUI.setTitle",
            vec![Value::Int(4242), Value::from("t")],
            "invalid ui handle: 4242",
        ),
        (
            "simUI.setPosition",
            vec![h.clone(), Value::from("x"), Value::Int(0)],
            "argument 2",
        ),
        (
            "simUI.setWidgetVisibility",
            vec![h.clone(), Value::Int(9), Value::Bool(true)],
            "invalid widget id: 9",
        ),
        (
            "simUI.getWidgetVisibility",
            vec![h.clone(), Value::Int(9)],
            "invalid widget id: 9",
        ),
        (
            "simUI.setButtonText",
            vec![h.clone(), Value::Int(2), Value::from("x")],
            "invalid widget type. expected button",
        ),
        (
            "simUI.setButtonText",
            vec![h.clone(), Value::Int(1), Value::Int(3)],
            "argument 3",
        ),
    ] {
        let e = call(&mut w, &ctx, name, &args).expect_err(name);
        assert!(e.contains(expect), "{name}: {e}");
        assert!(e.ends_with(&format!("(in function '{name}')")), "{e}");
    }
    let long = "x".repeat(gantry_sim_core::ui::MAX_TEXT_LEN + 1);
    assert!(call(&mut w, &ctx, "simUI.setTitle", &[h, Value::from(long)]).is_err());
}
