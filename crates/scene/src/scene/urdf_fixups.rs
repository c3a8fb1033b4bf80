//! Repairs for URDFs that PyBullet and ROS tools load but urdf-rs refuses, applied to the
//! text before parsing, each reported once per file.
//!
//! Public robot files are not all strictly valid: generated files keep xacro
//! expressions, and exporters write empty elements. A researcher whose file loads
//! everywhere else expects it to load here too, with a word about what was assumed.
//! Each repair is narrow (it matches one known pattern) and leaves every other byte as
//! it was, so line numbers in later errors still point into the user's file.

use std::borrow::Cow;

/// The text urdf-rs should parse, and one warning per kind of repair made.
pub(crate) fn repair(text: &str) -> (Cow<'_, str>, Vec<String>) {
    let mut warnings = Vec::new();
    let mut out = Cow::Borrowed(text);
    let (expanded, n) = expand_optenv(&out);
    if n > 0 {
        warnings.push(format!(
            "{n} xacro `$(optenv NAME DEFAULT)` expression(s) left in the file: each read as its DEFAULT (run xacro to use the environment)"
        ));
        out = Cow::Owned(expanded);
    }
    let (stripped, textures, strays) = drop_strays(&out);
    if textures > 0 {
        warnings.push(format!(
            "{textures} <texture> element(s) without a filename: ignored (nothing to draw)"
        ));
    }
    if strays > 0 {
        warnings.push(format!(
            "{strays} element(s) inside <geometry> that are not its shape (e.g. a <material>, which belongs in <visual>): ignored"
        ));
    }
    if textures + strays > 0 {
        out = Cow::Owned(stripped);
    }
    (out, warnings)
}

/// Replaces each `$(optenv NAME DEFAULT...)` by `DEFAULT...`, what xacro gives when the
/// variable is unset. Returns the text and the number replaced.
fn expand_optenv(text: &str) -> (String, usize) {
    const OPEN: &str = "$(optenv ";
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    let mut count = 0;
    while let Some(start) = rest.find(OPEN) {
        let after = &rest[start + OPEN.len()..];
        // NAME, then the default up to the closing parenthesis (xacro's defaults hold
        // no parentheses).
        let Some(close) = after.find(')') else { break };
        let body = &after[..close];
        let default = body.split_once(' ').map_or("", |(_, d)| d.trim());
        out.push_str(&rest[..start]);
        out.push_str(default);
        rest = &after[close + 1..];
        count += 1;
    }
    out.push_str(rest);
    (out, count)
}

/// Blanks out two kinds of element urdf-rs refuses: `<texture>` without a `filename`
/// (iCub's files carry `<texture />`) and anything after the shape inside `<geometry>`
/// (pybullet_data's racecar puts a `<material>` there). Returns the text and the number
/// of each removed; text that is not well-formed XML is returned as it is, for the
/// parser to report.
fn drop_strays(text: &str) -> (String, usize, usize) {
    let Ok(doc) = roxmltree::Document::parse_with_options(text, xml_options()) else {
        return (text.to_owned(), 0, 0);
    };
    let textures: Vec<_> = doc
        .descendants()
        .filter(|n| n.has_tag_name("texture") && n.attribute("filename").is_none())
        .map(|n| n.range())
        .collect();
    let strays: Vec<_> = doc
        .descendants()
        .filter(|n| n.has_tag_name("geometry"))
        .flat_map(|g| g.children().filter(roxmltree::Node::is_element).skip(1))
        .map(|n| n.range())
        .collect();
    let mut ranges: Vec<_> = textures.iter().chain(&strays).cloned().collect();
    ranges.sort_by_key(|r| r.start);
    let mut out = text.to_owned();
    // Back to front, so earlier ranges stay valid. Spaces in place of the element keep
    // every later line and column where it was (multi-line elements keep their line
    // breaks too).
    for r in ranges.iter().rev() {
        let blank: String = text[r.clone()]
            .chars()
            .map(|c| if c == '\n' { '\n' } else { ' ' })
            .collect();
        out.replace_range(r.clone(), &blank);
    }
    (out, textures.len(), strays.len())
}

/// How every URDF is parsed as XML: DTDs allowed (some exporters write one), which
/// roxmltree refuses by default. The fix-ups read the text first, so the options live
/// here and the importer uses them too.
pub(super) fn xml_options() -> roxmltree::ParsingOptions {
    roxmltree::ParsingOptions {
        allow_dtd: true,
        ..roxmltree::ParsingOptions::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn optenv_reads_as_its_default() {
        let text = r#"<origin rpy="$(optenv HUSKY_IMU_RPY 0 -1.5708 3.1416)" xyz="$(optenv X 0.19 0 0.149)"/>"#;
        let (out, warnings) = repair(text);
        assert_eq!(out, r#"<origin rpy="0 -1.5708 3.1416" xyz="0.19 0 0.149"/>"#);
        assert_eq!(warnings.len(), 1);
        assert!(warnings[0].starts_with("2 xacro"), "{warnings:?}");
    }

    #[test]
    fn empty_textures_are_blanked_in_place() {
        let text =
            "<robot name=\"r\">\n<material name=\"m\"><texture />\n<texture filename=\"a.png\"/></material>\n</robot>";
        let (out, warnings) = repair(text);
        assert_eq!(out.len(), text.len(), "lines and columns are kept");
        assert!(!out.contains("<texture />"));
        assert!(out.contains("<texture filename=\"a.png\"/>"));
        assert_eq!(warnings.len(), 1);
    }

    #[test]
    fn a_material_inside_geometry_is_dropped() {
        let text = "<robot name=\"r\"><link name=\"a\"><visual><geometry>\n<box size=\"1 1 1\"/>\n<material name=\"grey\"/>\n</geometry></visual></link></robot>";
        let (out, warnings) = repair(text);
        assert_eq!(out.lines().count(), text.lines().count());
        assert!(
            out.contains("<box size=\"1 1 1\"/>") && !out.contains("material"),
            "{out}"
        );
        assert_eq!(warnings.len(), 1);
        assert!(warnings[0].contains("inside <geometry>"), "{warnings:?}");
    }

    #[test]
    fn a_valid_file_is_borrowed_untouched() {
        let text = "<robot name=\"r\"><link name=\"a\"/></robot>";
        let (out, warnings) = repair(text);
        assert!(matches!(out, Cow::Borrowed(_)));
        assert!(warnings.is_empty());
    }

    #[test]
    fn an_unclosed_optenv_is_left_for_the_parser() {
        let (out, n) = expand_optenv("a=\"$(optenv X 1\"");
        assert_eq!((out.as_str(), n), ("a=\"$(optenv X 1\"", 0));
    }
}
