//! `bg-sim graph`: a model's bond graph drawn as SVG (or written as Graphviz DOT).
//!
//! Elements are drawn by their bond-graph symbol and name (`C: spring`, `1`, `Se: gravity`);
//! a domain kind gets the symbol its causal rule implies (a storage that imposes its effort
//! is a `C`, one that imposes its flow an `I`, a resistive one an `R`, …) with the kind's
//! name beneath. Every bond is a line with a half-arrow at its head (the direction of
//! positive power, `from -> to` in the file) and one causal stroke across the end that
//! *receives* the effort: the end opposite the element that sets the bond's effort
//! ([`bondgraph::CausalGraph::effort_setter`]). A signal an element reads is a dashed line
//! with a full arrowhead. A composite (`hydraulics.cylinder`, `manipulator.planar_arm`) is one
//! box with its exposed ports named where its bonds attach, or, expanded, a dashed frame
//! around its members.
//!
//! The layout is our own layered drawing ([`layout`]): composites expanded are laid out
//! on their own first and placed as one block. A PNG is that SVG rendered ([`png`]).

mod dot;
mod drawing;
pub mod layout;
mod place;
pub mod png;
mod svg;

pub use dot::dot;
pub use drawing::drawing;
pub use svg::svg;

use layout::Size;

/// Width of one character of the monospace font, in px per px of font size.
const CHAR_W: f64 = 0.6;
/// Font size of element labels (px).
const FONT: f64 = 13.0;
/// Font size of kind names, bond names and port names (px).
const SMALL: f64 = 10.0;
/// Length of the causal stroke (px).
const STROKE: f64 = 14.0;
/// Length of the half-arrow's barb (px).
const BARB: f64 = 11.0;

/// What a node of the drawing stands for.
#[derive(Clone, Debug, PartialEq, Eq)]
enum Shape {
    /// A bond-graph element drawn as its symbol and name.
    Element,
    /// A 0- or 1-junction: the symbol large, the name small.
    Junction,
    /// A signal block (no ports): a framed box.
    Block,
    /// A collapsed composite: a framed box with its kind.
    Composite,
}

/// One node: an element, or a collapsed composite.
#[derive(Clone, Debug)]
struct Node {
    /// Name in the model (global).
    name: String,
    /// First line: the symbol and the short name (`C: chamber_p`), or the junction's symbol.
    label: String,
    /// Second line, small: the kind (domain kinds, composites) or a junction's name.
    sub: Option<String>,
    shape: Shape,
    /// The expanded composite it belongs to.
    cluster: Option<usize>,
    size: Size,
}

/// Which end of a bond carries the causal stroke.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum End {
    Tail,
    Head,
}

/// A bond or a signal between two nodes.
#[derive(Clone, Debug)]
struct Link {
    from: usize,
    to: usize,
    /// `Some` for a bond: its name, dimension, causal stroke, and the composite port names at
    /// its ends (collapsed composites).
    bond: Option<BondLink>,
    /// A signal's name (`crane_act1.l1`).
    signal: String,
}

#[derive(Clone, Debug)]
struct BondLink {
    name: String,
    /// The name drawn: without its composite's prefix inside a frame.
    label: String,
    dim: usize,
    stroke: Option<End>,
    ports: [Option<String>; 2],
}

/// An expanded composite: a frame around its members.
#[derive(Clone, Debug)]
struct Cluster {
    name: String,
    kind: String,
    members: Vec<usize>,
}

/// A model's bond graph ready to draw: nodes, bonds and signals, composites.
#[derive(Clone, Debug)]
pub struct Drawing {
    title: String,
    nodes: Vec<Node>,
    links: Vec<Link>,
    clusters: Vec<Cluster>,
    /// Why there are no causal strokes, if causality could not be assigned.
    problem: Option<String>,
}

impl Drawing {
    /// Bonds drawn (each with one half-arrow and, if causality was assigned, one stroke).
    #[must_use]
    pub fn n_bonds(&self) -> usize {
        self.links.iter().filter(|l| l.bond.is_some()).count()
    }

    /// Why no causal strokes are drawn (the causality error), if so.
    #[must_use]
    pub fn problem(&self) -> Option<&str> {
        self.problem.as_deref()
    }
}

/// Width of a text in px (monospace estimate).
fn text_w(s: &str, font: f64) -> f64 {
    s.chars().count() as f64 * CHAR_W * font
}

/// What `bg-sim graph` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// An SVG drawing (drawn here, no Graphviz needed).
    Svg,
    /// Graphviz DOT, for `dot -Tsvg` or `dot -Tpdf`.
    Dot,
    /// The SVG drawing rendered to pixels (no viewer or Graphviz needed).
    Png,
}

impl Format {
    fn extension(self) -> &'static str {
        match self {
            Format::Svg => "svg",
            Format::Dot => "dot",
            Format::Png => "png",
        }
    }
}

/// What [`write`] wrote.
#[derive(Clone, Debug)]
pub struct Written {
    /// The file.
    pub path: std::path::PathBuf,
    /// Elements or composite boxes drawn.
    pub nodes: usize,
    /// Bonds drawn.
    pub bonds: usize,
    /// Why there are no causal strokes, if so.
    pub problem: Option<String>,
}

/// `bg-sim graph`: load `model` (with `--set` overrides) as far as its causality, draw it and
/// write it to `out` (default `out/<model>.svg`, `.dot` or `.png`); the format is `format`,
/// else the extension of `out` (`.dot`/`.gv`: DOT, `.png`: PNG), else SVG. A PNG is the SVG
/// rendered at `scale` pixels per SVG pixel.
pub fn write(
    model: &std::path::Path,
    out: Option<&std::path::Path>,
    expand: bool,
    format: Option<Format>,
    scale: f32,
    set: &[String],
) -> Result<Written, String> {
    let format = format.unwrap_or_else(|| {
        match out
            .and_then(|p| p.extension())
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("dot" | "gv") => Format::Dot,
            Some("png") => Format::Png,
            _ => Format::Svg,
        }
    });
    let path = out.map_or_else(
        || {
            let stem = model
                .file_stem()
                .map_or_else(|| "model".into(), |s| s.to_string_lossy().into_owned());
            std::path::PathBuf::from("out").join(format!("{stem}.{}", format.extension()))
        },
        std::path::Path::to_path_buf,
    );
    if path == model {
        return Err(format!(
            "refusing to write the drawing over the model file {}",
            model.display()
        ));
    }
    let s = bg_model::structure(model, &crate::registry(), set).map_err(|e| e.to_string())?;
    let d = drawing(&s, expand);
    let bytes = match format {
        Format::Svg => svg(&d).into_bytes(),
        Format::Dot => dot(&d).into_bytes(),
        Format::Png => png::png(&svg(&d), scale)?,
    };
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| format!("cannot write {}: {e}", dir.display()))?;
    }
    std::fs::write(&path, bytes).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    Ok(Written {
        path,
        nodes: d.nodes.len(),
        bonds: d.n_bonds(),
        problem: d.problem.clone(),
    })
}
