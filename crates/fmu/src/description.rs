//! What an FMU of a model declares: its variables with their value references
//! ([`Description::of`]), and `modelDescription.xml` for FMI 2.0 and 3.0
//! ([`Description::xml`]). The export (`bg-sim fmu`) and the library running the FMU compute
//! the table from the same model text with the same code, so their value references agree;
//! the token ([`token`]) binds the two.
//!
//! The variables, in value-reference order:
//! 0. `time` (causality independent);
//! 1. the `[inputs]` (causality input, start = the input's default, its unit);
//! 2. the `[outputs]` columns (causality output);
//! 3. the `[parameters]` (causality parameter, variability fixed, start = their value).
//!
//! A name already taken by an earlier group is prefixed by its section (`outputs.F`,
//! `parameters.k`); an output column that only repeats an input of the same name is that
//! input, not a second variable.

use std::fmt::Write as _;

use bg_model::Model;

/// The FMI version of an FMU.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FmiVersion {
    /// FMI 2.0 co-simulation.
    V2,
    /// FMI 3.0 co-simulation.
    V3,
}

impl FmiVersion {
    /// The platform folder of Linux x86-64 under `binaries/`.
    #[must_use]
    pub fn platform(self) -> &'static str {
        match self {
            Self::V2 => "linux64",
            Self::V3 => "x86_64-linux",
        }
    }
}

/// What a variable is in the model.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Role {
    /// Simulation time.
    Time,
    /// Input `i` of the equations (`[inputs]`, in order).
    Input(usize),
    /// Column `i` of the model's `[outputs]`.
    Output(usize),
    /// The `[parameters]` entry of this name.
    Parameter(String),
}

/// One model variable of the FMU (all are Real / Float64).
#[derive(Clone, Debug, PartialEq)]
pub struct Variable {
    /// Its name in the FMU.
    pub name: String,
    /// Its value reference (its index in [`Description::variables`]).
    pub vr: u32,
    /// What it is.
    pub role: Role,
    /// Start value (inputs and parameters).
    pub start: Option<f64>,
    /// Unit as the model writes it (empty if unknown).
    pub unit: String,
    /// Description.
    pub description: String,
}

/// The FMU's view of a model; see the module doc.
#[derive(Clone, Debug, PartialEq)]
pub struct Description {
    /// `modelName`: the model's title, else the file stem.
    pub model_name: String,
    /// The model's description, if any.
    pub description: String,
    /// The variables, by value reference.
    pub variables: Vec<Variable>,
    /// Default experiment: start and stop time, step size (the model's `dt_out`), tolerance.
    pub start_time: f64,
    /// Stop time (`t_end`).
    pub stop_time: f64,
    /// Communication step (`dt_out`).
    pub step_size: f64,
    /// Relative tolerance (`rtol`).
    pub tolerance: f64,
    /// GUID (FMI 2) / instantiation token (FMI 3).
    pub token: String,
}

/// The GUID of a model text: two 64-bit FNV-1a hashes (stable across builds, unlike
/// `std`'s hasher) of the text and of this crate's version, in GUID form.
#[must_use]
pub fn token(text: &str) -> String {
    let fnv = |seed: u64| {
        let mut h = 0xcbf2_9ce4_8422_2325_u64 ^ seed;
        for b in env!("CARGO_PKG_VERSION")
            .bytes()
            .chain([0])
            .chain(text.bytes())
        {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
        h
    };
    let (a, b) = (fnv(0), fnv(0x9e37_79b9_7f4a_7c15));
    format!(
        "{{{:08x}-{:04x}-{:04x}-{:04x}-{:012x}}}",
        a >> 32,
        (a >> 16) & 0xffff,
        a & 0xffff,
        b >> 48,
        b & 0xffff_ffff_ffff
    )
}

impl Description {
    /// The description of `model`, loaded from `text` (the file as shipped); `stem` names
    /// the model when it has no title.
    #[must_use]
    pub fn of(model: &Model, text: &str, stem: &str) -> Self {
        let mut variables: Vec<Variable> = Vec::new();
        let mut push = |name: String, section: &str, role, start, unit: String, description| {
            let taken = |n: &str, v: &[Variable]| v.iter().any(|x| x.name == n);
            let name = if taken(&name, &variables) {
                format!("{section}.{name}")
            } else {
                name
            };
            let vr = u32::try_from(variables.len()).unwrap_or(u32::MAX);
            variables.push(Variable {
                name,
                vr,
                role,
                start,
                unit,
                description,
            });
        };
        push(
            "time".into(),
            "",
            Role::Time,
            None,
            "s".into(),
            "simulation time".into(),
        );
        let eqs = &model.equations;
        let inputs = eqs.inputs();
        for (i, u) in inputs.iter().enumerate() {
            push(
                u.name.clone(),
                "inputs",
                Role::Input(i),
                Some(u.default),
                u.unit.clone(),
                u.description.clone(),
            );
        }
        for (i, o) in model.outputs.iter().enumerate() {
            let repeats_input = inputs.iter().any(|u| u.name == o.name)
                && eqs.probe(&o.name).is_some_and(|p| p == o.probe);
            if repeats_input {
                continue;
            }
            push(
                o.name.clone(),
                "outputs",
                Role::Output(i),
                None,
                String::new(),
                String::new(),
            );
        }
        for (name, value) in &model.parameters {
            push(
                name.clone(),
                "parameters",
                Role::Parameter(name.clone()),
                Some(*value),
                String::new(),
                String::new(),
            );
        }
        let s = &model.settings;
        Self {
            model_name: model
                .title
                .clone()
                .filter(|t| !t.trim().is_empty())
                .unwrap_or_else(|| stem.to_owned()),
            description: model.description.clone().unwrap_or_default(),
            variables,
            start_time: s.t_start,
            stop_time: s.t_end,
            step_size: s.dt_out,
            tolerance: s.rtol,
            token: token(text),
        }
    }

    /// The variable of value reference `vr`.
    #[must_use]
    pub fn variable(&self, vr: u32) -> Option<&Variable> {
        self.variables.get(usize::try_from(vr).ok()?)
    }

    /// The variables of one causality.
    fn outputs(&self) -> impl Iterator<Item = &Variable> {
        self.variables
            .iter()
            .filter(|v| matches!(v.role, Role::Output(_)))
    }

    /// `modelDescription.xml` for `version`, the library being `model_identifier`.
    #[must_use]
    pub fn xml(&self, version: FmiVersion, model_identifier: &str) -> String {
        let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
        let tool = concat!("bg-sim ", env!("CARGO_PKG_VERSION"));
        let common = format!(
            "modelName=\"{}\" description=\"{}\" generationTool=\"{tool}\" variableNamingConvention=\"flat\"",
            esc(&self.model_name),
            esc(&first_paragraph(&self.description)),
        );
        let mut units: Vec<&str> = self
            .variables
            .iter()
            .map(|v| v.unit.as_str())
            .filter(|u| !u.is_empty())
            .collect();
        units.sort_unstable();
        units.dedup();
        let unit_defs = if units.is_empty() {
            String::new()
        } else {
            let mut u = String::from("  <UnitDefinitions>\n");
            for n in &units {
                let _ = writeln!(u, "    <Unit name=\"{}\"/>", esc(n));
            }
            u.push_str("  </UnitDefinitions>\n");
            u
        };
        let experiment = format!(
            "  <DefaultExperiment startTime=\"{}\" stopTime=\"{}\" stepSize=\"{}\" tolerance=\"{}\"/>\n",
            num(self.start_time),
            num(self.stop_time),
            num(self.step_size),
            num(self.tolerance)
        );
        match version {
            FmiVersion::V2 => {
                let _ = writeln!(
                    x,
                    "<fmiModelDescription fmiVersion=\"2.0\" guid=\"{}\" {common} numberOfEventIndicators=\"0\">",
                    self.token
                );
                let _ = writeln!(
                    x,
                    "  <CoSimulation modelIdentifier=\"{}\" canHandleVariableCommunicationStepSize=\"true\" canInterpolateInputs=\"false\" canGetAndSetFMUstate=\"true\" canSerializeFMUstate=\"false\" providesDirectionalDerivative=\"false\"/>",
                    esc(model_identifier)
                );
                x.push_str(&unit_defs);
                x.push_str(&experiment);
                x.push_str("  <ModelVariables>\n");
                for v in &self.variables {
                    let _ = writeln!(
                        x,
                        "    <!-- index {} -->\n    <ScalarVariable name=\"{}\" valueReference=\"{}\"{}{}>\n      <Real{}{}/>\n    </ScalarVariable>",
                        v.vr + 1,
                        esc(&v.name),
                        v.vr,
                        describe(&v.description),
                        attributes(&v.role),
                        unit(&v.unit),
                        v.start.map(|s| format!(" start=\"{}\"", num(s))).unwrap_or_default(),
                    );
                }
                x.push_str("  </ModelVariables>\n  <ModelStructure>\n");
                let outputs: Vec<_> = self.outputs().collect();
                if !outputs.is_empty() {
                    x.push_str("    <Outputs>\n");
                    for v in &outputs {
                        let _ = writeln!(x, "      <Unknown index=\"{}\"/>", v.vr + 1);
                    }
                    x.push_str("    </Outputs>\n    <InitialUnknowns>\n");
                    for v in &outputs {
                        let _ = writeln!(x, "      <Unknown index=\"{}\"/>", v.vr + 1);
                    }
                    x.push_str("    </InitialUnknowns>\n");
                }
                x.push_str("  </ModelStructure>\n</fmiModelDescription>\n");
            }
            FmiVersion::V3 => {
                let _ = writeln!(
                    x,
                    "<fmiModelDescription fmiVersion=\"3.0\" instantiationToken=\"{}\" {common}>",
                    self.token
                );
                let _ = writeln!(
                    x,
                    "  <CoSimulation modelIdentifier=\"{}\" canHandleVariableCommunicationStepSize=\"true\" canGetAndSetFMUState=\"true\" canSerializeFMUState=\"false\" providesDirectionalDerivatives=\"false\" providesAdjointDerivatives=\"false\" hasEventMode=\"false\" providesIntermediateUpdate=\"false\"/>",
                    esc(model_identifier)
                );
                x.push_str(&unit_defs);
                x.push_str(&experiment);
                x.push_str("  <ModelVariables>\n");
                for v in &self.variables {
                    let _ = writeln!(
                        x,
                        "    <Float64 name=\"{}\" valueReference=\"{}\"{}{}{}{}/>",
                        esc(&v.name),
                        v.vr,
                        describe(&v.description),
                        attributes(&v.role),
                        unit(&v.unit),
                        v.start
                            .map(|s| format!(" start=\"{}\"", num(s)))
                            .unwrap_or_default(),
                    );
                }
                x.push_str("  </ModelVariables>\n  <ModelStructure>\n");
                for v in self.outputs() {
                    let _ = writeln!(x, "    <Output valueReference=\"{}\"/>", v.vr);
                }
                for v in self.outputs() {
                    let _ = writeln!(x, "    <InitialUnknown valueReference=\"{}\"/>", v.vr);
                }
                x.push_str("  </ModelStructure>\n</fmiModelDescription>\n");
            }
        }
        x
    }
}

/// Causality, variability and initial of a role (the same words in FMI 2 and 3).
fn attributes(role: &Role) -> &'static str {
    match role {
        Role::Time => " causality=\"independent\" variability=\"continuous\"",
        Role::Input(_) => " causality=\"input\" variability=\"continuous\"",
        Role::Output(_) => " causality=\"output\" variability=\"continuous\"",
        Role::Parameter(_) => " causality=\"parameter\" variability=\"fixed\" initial=\"exact\"",
    }
}

fn describe(d: &str) -> String {
    if d.is_empty() {
        String::new()
    } else {
        format!(" description=\"{}\"", esc(d))
    }
}

fn unit(u: &str) -> String {
    if u.is_empty() {
        String::new()
    } else {
        format!(" unit=\"{}\"", esc(u))
    }
}

/// The first paragraph of a description, on one line.
fn first_paragraph(d: &str) -> String {
    d.trim()
        .split("\n\n")
        .next()
        .unwrap_or("")
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}

/// A number as XML reads it back exactly (Rust's shortest round-trip form).
fn num(v: f64) -> String {
    format!("{v:?}")
}

/// `s` escaped for an XML attribute.
fn esc(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&apos;"),
            '\n' | '\r' | '\t' => o.push(' '),
            c if (c as u32) < 0x20 => {}
            c => o.push(c),
        }
    }
    o
}
