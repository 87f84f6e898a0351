//! Assembling a page: the template with its style, script, title, read-out and data filled in.
//! Both pages share the template, the style and the viewer's core script (`viewer.js`: the
//! projection, painter's order, the arm, the cell and the controls); each adds its own script
//! (`motion.js`, `job.js`) and read-out.

use crate::input::ViewerInput;
use crate::job::{JobScene, JobViewerInput};
use crate::scene::Scene;

const TEMPLATE: &str = include_str!("viewer.html");
const STYLE: &str = include_str!("viewer.css");
/// The core both pages run: error reporting, projection, painter's order, the arm, the cell,
/// the timeline, the controls.
const CORE: &str = include_str!("viewer.js");
/// The motion page on the core.
const MOTION: &str = include_str!("motion.js");
/// The job page on the core.
const JOB: &str = include_str!("job.js");

/// The motion page's read-out: (label as HTML, element id).
const MOTION_READOUT: &[(&str, &str)] = &[
    ("time", "r-time"),
    ("path", "r-path"),
    ("line error", "r-lateral"),
    ("tool angle", "r-angle"),
    ("&rho;", "r-rho"),
    ("step", "r-step"),
];

/// The job page's read-out: (label as HTML, element id).
const JOB_READOUT: &[(&str, &str)] = &[
    ("time", "r-time"),
    ("segment", "r-segment"),
    ("stroke", "r-stroke"),
    ("line error", "r-lateral"),
    ("tool angle", "r-angle"),
    ("sample", "r-step"),
];

/// The viewer page for `input`: one self-contained HTML document (inline style, script and
/// data; no external references).
pub fn render_html(input: &ViewerInput<'_>) -> String {
    let scene = Scene::new(input);
    let json = serde_json::to_string(&scene).expect("the scene holds only numbers and strings");
    page(input.title, MOTION_READOUT, MOTION, &json)
}

/// The job page for `input`: one self-contained HTML document (inline style, script and data;
/// no external references) that plays the whole program at its timing: the arm, every stroke
/// on the part (its stretches drawn solid, the rest faint), the ink laid so far, the TCP's
/// pen-up moves dashed, the segment under way named, and the work plates and obstacles.
///
/// # Panics
///
/// Where the input disagrees with itself: a stroke segment naming a stroke `input.strokes`
/// lacks or without a task, or `input.reached` not one entry per stroke.
pub fn render_job_html(input: &JobViewerInput<'_>) -> String {
    let scene = JobScene::new(input);
    let json = serde_json::to_string(&scene).expect("the scene holds only numbers and strings");
    page(input.title, JOB_READOUT, JOB, &json)
}

/// The template filled with `title`, the read-out rows, the core script followed by `script`,
/// and `json` as the page's data.
fn page(title: &str, readout: &[(&str, &str)], script: &str, json: &str) -> String {
    let rows: String = readout
        .iter()
        .map(|(label, id)| {
            format!("    <div><span class=\"key\">{label}</span> <span id=\"{id}\"></span></div>\n")
        })
        .collect();
    fill(
        TEMPLATE,
        &[
            ("TITLE", &escape_html(title)),
            ("STYLE", STYLE),
            ("READOUT", rows.trim_end()),
            ("SCRIPT", &format!("{CORE}\n{script}")),
            ("DATA", &escape_script_json(json)),
        ],
    )
}

/// Replaces every `{{NAME}}` of `template` by its value in one pass, so that a value that
/// happens to contain a placeholder is never expanded again.
fn fill(template: &str, values: &[(&str, &str)]) -> String {
    let mut out =
        String::with_capacity(template.len() + values.iter().map(|(_, v)| v.len()).sum::<usize>());
    let mut rest = template;
    while let Some(open) = rest.find("{{") {
        out.push_str(&rest[..open]);
        let after = &rest[open + 2..];
        let close = after
            .find("}}")
            .unwrap_or_else(|| panic!("viewer.html: unclosed placeholder at '{}'", &rest[open..]));
        let name = &after[..close];
        let value = values
            .iter()
            .find(|(key, _)| *key == name)
            .unwrap_or_else(|| panic!("viewer.html: unknown placeholder '{{{{{name}}}}}'"))
            .1;
        out.push_str(value);
        rest = &after[close + 2..];
    }
    out.push_str(rest);
    out
}

/// Text made safe inside HTML element content and attribute values.
fn escape_html(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

/// JSON made safe inside a `<script>` element: every `<` (which only occurs inside strings) is
/// written as the JSON escape `\u003c`, so no `</script>` or `<!--` can end or confuse the element.
fn escape_script_json(json: &str) -> String {
    json.replace('<', "\\u003c")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fill_substitutes_each_placeholder_once() {
        let page = fill("<a>{{X}}</a>{{Y}}", &[("X", "{{Y}}"), ("Y", "y")]);
        assert_eq!(page, "<a>{{Y}}</a>y");
    }

    #[test]
    fn template_uses_exactly_the_known_placeholders() {
        let page = fill(
            TEMPLATE,
            &[
                ("TITLE", "t"),
                ("STYLE", "s"),
                ("READOUT", "r"),
                ("SCRIPT", "j"),
                ("DATA", "{}"),
            ],
        );
        assert!(!page.contains("{{"), "a placeholder was left unfilled");
    }

    #[test]
    fn script_and_style_cannot_end_their_elements() {
        for script in [CORE, MOTION, JOB] {
            assert!(!script.to_ascii_lowercase().contains("</script"));
            assert!(!script.contains("<!--"));
        }
        assert!(!STYLE.to_ascii_lowercase().contains("</style"));
    }

    #[test]
    fn title_and_json_are_escaped() {
        assert_eq!(
            escape_html(r#"a<b>&"c"'"#),
            "a&lt;b&gt;&amp;&quot;c&quot;&#39;"
        );
        let json = serde_json::to_string("</script><!--").unwrap();
        let escaped = escape_script_json(&json);
        assert!(!escaped.contains('<'));
        assert_eq!(
            serde_json::from_str::<String>(&escaped).unwrap(),
            "</script><!--"
        );
    }
}
