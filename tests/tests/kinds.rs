//! Every registered kind against its declaration: each declared parameter is listed by
//! `bg-sim kinds NAME` and in the documentation's generated table (which must equal what
//! the declaration gives), and an unknown key, a misspelt key and an out-of-range value are
//! each refused with the file, line, element and a hint.
//!
//! The documentation's tables sit between `<!-- parameters of KIND … -->` and
//! `<!-- end of parameters -->`; `BG_UPDATE_DOCS=1 cargo test -p bg-tests --test kinds`
//! rewrites them from the declarations.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::PathBuf;

use bg_model::{parameter_table, ErrorKind, Model, ModelError};
use bondgraph::kind::{KindDecl, ParamDecl, ParamType, Range};

fn kinds() -> Vec<KindDecl> {
    bg_sim::registry().kinds().copied().collect()
}

fn docs() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(bg_tests::root().join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    v.sort();
    v
}

const END: &str = "<!-- end of parameters -->";

fn begin(kind: &str) -> String {
    format!("<!-- parameters of {kind}: generated from its declaration")
}

/// The generated block of `kind`: (file, byte range of the table between the markers).
fn block(kind: &str) -> Option<(PathBuf, std::ops::Range<usize>)> {
    let b = begin(kind);
    for path in docs() {
        let text = std::fs::read_to_string(&path).unwrap();
        if let Some(i) = text.find(&b) {
            let start = i + text[i..].find("-->").unwrap() + 3;
            let end = start
                + text[start..]
                    .find(END)
                    .unwrap_or_else(|| panic!("{kind}: no end marker in {}", path.display()));
            return Some((path, start..end));
        }
    }
    None
}

#[test]
fn every_kind_has_its_generated_parameter_table_in_the_docs() {
    let update = std::env::var_os("BG_UPDATE_DOCS").is_some();
    let mut problems = Vec::new();
    for k in kinds() {
        let want = format!("\n{}", parameter_table(&k));
        match block(k.name) {
            None => problems.push(format!(
                "`{}` has no parameter table in docs/: add\n{} (see `bg-sim kinds {}`) -->\n{END}\nto its section and run BG_UPDATE_DOCS=1 cargo test -p bg-tests --test kinds",
                k.name,
                begin(k.name),
                k.name
            )),
            Some((path, range)) => {
                let text = std::fs::read_to_string(&path).unwrap();
                if text[range.clone()] != want {
                    if update {
                        let new = format!("{}{want}{}", &text[..range.start], &text[range.end..]);
                        std::fs::write(&path, new).unwrap();
                    } else {
                        problems.push(format!(
                            "the table of `{}` in {} differs from its declaration: run BG_UPDATE_DOCS=1 cargo test -p bg-tests --test kinds",
                            k.name,
                            path.display()
                        ));
                    }
                }
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

fn names(prefix: &str, params: &[ParamDecl], out: &mut Vec<String>) {
    for d in params {
        out.push(format!("{prefix}{}", d.name));
        if let Some(f) = d.fields() {
            names(&format!("{prefix}{}.", d.name), f, out);
        }
    }
}

#[test]
fn kinds_name_lists_every_declared_parameter_and_builds_the_example() {
    let r = bg_sim::registry();
    for k in kinds() {
        let text = bg_sim::kinds::report(&r, k.name).unwrap_or_else(|e| panic!("{}: {e}", k.name));
        let mut all = Vec::new();
        names("", k.params, &mut all);
        for n in all {
            assert!(
                text.contains(&format!("`{n}`")),
                "`bg-sim kinds {}` does not list `{n}`:\n{text}",
                k.name
            );
        }
        assert!(text.contains("ports:"), "{}", k.name);
    }
}

/// A one-element model with `k`'s example and `extra` appended to its parameters.
fn load_with(k: &KindDecl, example: &str) -> Result<Model, ModelError> {
    let text = format!(
        "title = \"kinds\"\n[elements]\nx = {{ kind = \"{}\", {} }}\n",
        k.name, example
    );
    Model::from_text("kinds.toml", &text, &bg_sim::registry(), &[])
}

fn assert_positioned(k: &KindDecl, e: &ModelError, what: &str) {
    assert_eq!(e.file, "kinds.toml", "{}: {what}: {e}", k.name);
    assert_eq!(e.line, Some(3), "{}: {what}: {e}", k.name);
    assert_eq!(e.element.as_deref(), Some("x"), "{}: {what}: {e}", k.name);
    assert!(
        e.hint.as_deref().is_some_and(|h| !h.is_empty()),
        "{}: {what}: no hint: {e}",
        k.name
    );
}

#[test]
fn unknown_misspelt_and_out_of_range_keys_are_refused_with_line_element_and_hint() {
    let mut ranged = 0;
    for k in kinds() {
        let sep = if k.example.is_empty() { "" } else { ", " };
        // unknown
        let e = load_with(&k, &format!("{}{sep}zz_not_a_parameter = 1", k.example))
            .err()
            .unwrap_or_else(|| panic!("{}: unknown key accepted", k.name));
        assert_eq!(e.kind, ErrorKind::ExtraParameter, "{}: {e}", k.name);
        assert_positioned(&k, &e, "unknown key");
        // misspelt: a declared number given in the example, with one letter doubled
        if let Some(d) = k.params.iter().find(|d| {
            d.ty == ParamType::Number
                && k.example.contains(&format!("{} =", d.name))
                && d.name.len() > 1
        }) {
            let typo = format!("{}{}", d.name, d.name.chars().last().unwrap());
            let text = k
                .example
                .replacen(&format!("{} =", d.name), &format!("{typo} ="), 1);
            let e = load_with(&k, &text)
                .err()
                .unwrap_or_else(|| panic!("{}: `{typo}` accepted", k.name));
            assert_positioned(&k, &e, "misspelt key");
            assert!(
                e.hint
                    .as_deref()
                    .unwrap_or("")
                    .contains(&format!("`{}`", d.name)),
                "{}: the hint should name `{}`: {e}",
                k.name,
                d.name
            );
        }
        // out of range: a declared number with a bound
        if let Some(d) = k.params.iter().find(|d| {
            matches!(d.ty, ParamType::Number) && d.range != Range::ANY && d.range.lo.is_finite()
        }) {
            ranged += 1;
            let bad = if d.range.lo_open {
                d.range.lo
            } else {
                d.range.lo - 1.0
            };
            let text = if k.example.contains(&format!("{} =", d.name)) {
                let start = k.example.find(&format!("{} =", d.name)).unwrap();
                let rest = &k.example[start..];
                let end = rest.find(',').map_or(k.example.len(), |i| start + i);
                format!(
                    "{}{} = {bad}{}",
                    &k.example[..start],
                    d.name,
                    &k.example[end..]
                )
            } else {
                format!("{}{sep}{} = {bad}", k.example, d.name)
            };
            let e = load_with(&k, &text)
                .err()
                .unwrap_or_else(|| panic!("{}: {} = {bad} accepted", k.name, d.name));
            assert_eq!(e.kind, ErrorKind::BadParameter, "{}: {e}", k.name);
            assert_positioned(&k, &e, "out of range");
            assert!(
                e.message.contains(&d.range.to_string()),
                "{}: the message should name the range {}: {e}",
                k.name,
                d.range
            );
        }
    }
    assert!(ranged >= 10, "only {ranged} kinds have a bounded number");
}

#[test]
fn a_value_with_a_unit_is_converted_and_a_wrong_unit_is_refused() {
    let text = r#"
[elements]
src = { kind = "Sf", f = 0.0 }
oil = { kind = "hydraulics.chamber", volume = "1 L", beta = "15000 bar", p0 = "10 bar" }
[bonds]
b = "src -> oil"
[simulation]
t_end = 1.0
"#;
    let m = Model::from_text("units.toml", text, &bg_sim::registry(), &[]).unwrap();
    let x0 = &m.x0;
    assert!(
        (x0[0] - 1e6).abs() <= 1e-9,
        "p0 = \"10 bar\" gave {}",
        x0[0]
    );
    let k = bg_sim::registry()
        .get("hydraulics.chamber")
        .copied()
        .unwrap();
    let e = load_with(&k, "volume = 1e-3, beta = \"3 m\"")
        .err()
        .unwrap();
    assert_eq!(e.kind, ErrorKind::BadParameter, "{e}");
    assert!(
        e.message.contains("pressure") && e.message.contains("length"),
        "{e}"
    );
    assert_positioned(&k, &e, "wrong unit");
}

/// The symbol a parameter's doc line gives it: its last word before any parenthesis when
/// that word is one letter, optionally subscripted, and follows a noun (`x` in "relative
/// opening x (not clamped)"); after an operator or a preposition ("l = l0 + s", "1 P to A",
/// "at p_max") the word names something else.
fn doc_symbol(doc: &str) -> Option<&str> {
    const NOT_NOUNS: [&str; 8] = ["to", "at", "of", "from", "by", "and", "or", "passes"];
    let head = doc.split('(').next().unwrap_or(doc);
    let mut words = head.split_whitespace().rev();
    let last = words.next()?;
    let before = words.next()?;
    let noun = before.chars().all(char::is_alphabetic) && !NOT_NOUNS.contains(&before);
    let mut parts = last.splitn(2, '_');
    let letter = parts.next()?;
    let short = letter.chars().count() == 1 && letter.chars().all(char::is_alphabetic);
    (noun && short && parts.next().is_none_or(|s| !s.is_empty())).then_some(last)
}

/// The ASCII words of a law (`Q`, `x`, `regRoot`, `P_a`): maximal runs of letters, digits
/// and `_`; Greek letters, sub- and superscripts and operators separate them.
fn law_words(law: &str) -> Vec<&str> {
    law.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .filter(|w| !w.is_empty())
        .collect()
}

/// Every law row of the docs: (file, line, kind, law) for each table row whose first cell
/// names kinds in backticks, in a table with a `law` column.
fn law_rows() -> Vec<(String, usize, String, String)> {
    let mut rows = Vec::new();
    for path in docs() {
        let text = std::fs::read_to_string(&path).unwrap();
        let file = path.file_name().unwrap().to_string_lossy().into_owned();
        let mut law_col = None;
        for (i, line) in text.lines().enumerate() {
            if !line.starts_with('|') {
                law_col = None;
                continue;
            }
            let cells: Vec<&str> = line.trim_matches('|').split('|').map(str::trim).collect();
            if law_col.is_none() {
                law_col = cells.iter().position(|c| *c == "law");
                continue;
            }
            let Some(col) = law_col else { continue };
            for kind in cells[0].split(',').map(str::trim) {
                if let Some(k) = kind.strip_prefix('`').and_then(|k| k.strip_suffix('`')) {
                    if let Some(law) = cells.get(col) {
                        rows.push((file.clone(), i + 1, k.to_owned(), (*law).to_owned()));
                    }
                }
            }
        }
    }
    rows
}

/// Docs and declarations cannot drift apart on a law's names. The rule: a kind's law — its
/// row in a docs table with a `law` column, and its declaration's one-line summary — writes
/// each parameter by its key (`opening`) or by a Greek or literature symbol (α for `alpha`),
/// never by a second ASCII name. A parameter's ASCII symbol is the last word of its doc line
/// before any parenthesis when that word is one letter, optionally subscripted (`x` in
/// "relative opening x"); where it differs from the key, the law must not use it, because the
/// model file spells it otherwise (issue 24 item 3: the orifice's law wrote `x` for
/// `opening`). Other ASCII words of a law (port efforts and flows `P_a`, `Q`, states,
/// functions such as `regRoot`) are not parameters and pass. Rows naming element types
/// that are not registered kinds (the arm's internal fields in `manipulator.md`) are skipped.
#[test]
fn every_law_names_its_parameters_by_their_keys() {
    let kinds = kinds();
    let mut problems = Vec::new();
    let mut laws: Vec<(String, &KindDecl, String)> = Vec::new();
    for (file, line, kind, law) in law_rows() {
        if let Some(k) = kinds.iter().find(|k| k.name == kind) {
            laws.push((format!("{file}:{line}"), k, law));
        }
    }
    for k in &kinds {
        laws.push((
            format!("declaration of {}", k.name),
            k,
            k.summary.to_owned(),
        ));
    }
    let mut checked = 0;
    for (at, k, law) in &laws {
        let words = law_words(law);
        for d in k.params {
            let Some(sym) = doc_symbol(d.doc) else {
                continue;
            };
            if sym != d.name && words.contains(&sym) {
                problems.push(format!(
                    "{at}: the law of {} writes `{sym}` for the parameter `{}` (\"{}\"): write `{}`",
                    k.name, d.name, d.doc, d.name
                ));
            }
            checked += 1;
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    let rows = laws.len() - kinds.len();
    assert!(
        rows >= 25,
        "only {rows} law rows found in the docs: did the tables move?"
    );
    assert!(checked >= 20, "only {checked} parameter symbols checked");
    assert_eq!(doc_symbol("relative opening x (not clamped)"), Some("x"));
}
