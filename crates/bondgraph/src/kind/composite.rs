//! Composites: a sub-graph that one model-file entry expands into — a cylinder with its
//! chambers, piston and leakage; an arm with its fields — with the ports it exposes.

use crate::Element;

/// The global name of member `local` of composite `instance`: `<instance>_<local>`
/// (`cyl1` + `piston_chamber` → `cyl1_piston_chamber`). States and signals of members are
/// addressed through it (`cyl1_piston_chamber.p`). The one place this rule is written.
#[must_use]
pub fn member_name(instance: &str, local: &str) -> String {
    format!("{instance}_{local}")
}

/// A bond end `local` or `local.port` in global names.
fn member_end(instance: &str, end: &str) -> String {
    match end.split_once('.') {
        Some((el, port)) => format!("{}.{port}", member_name(instance, el)),
        None => member_name(instance, end),
    }
}

/// A sub-graph in local names: members, internal bonds and exposed ports.
#[derive(Debug, Default)]
pub struct Composite {
    /// Members: local name and element.
    pub elements: Vec<(String, Box<dyn Element>)>,
    /// Internal bonds: local bond name, from and to as `local` or `local.port`.
    pub bonds: Vec<(String, String, String)>,
    /// Exposed ports: the name the model file uses (`cyl1.mech` is port `mech`) and the
    /// member port it stands for (`local` or `local.port`), left unbonded inside.
    pub ports: Vec<(String, String)>,
}

/// A composite in global names ([`Composite::expand`]).
#[derive(Debug, Default)]
pub struct Expanded {
    /// Members: global name and element.
    pub elements: Vec<(String, Box<dyn Element>)>,
    /// Internal bonds: global bond name, from and to.
    pub bonds: Vec<(String, String, String)>,
    /// Exposed ports: port name and the member port (global) it stands for.
    pub ports: Vec<(String, String)>,
}

impl Composite {
    /// Add a member.
    pub fn element(&mut self, local: &str, element: impl Element + 'static) -> &mut Self {
        self.elements.push((local.to_owned(), Box::new(element)));
        self
    }
    /// Add a boxed member.
    pub fn boxed(&mut self, local: &str, element: Box<dyn Element>) -> &mut Self {
        self.elements.push((local.to_owned(), element));
        self
    }
    /// Add an internal bond `from -> to` (local names, `name.port` for a port).
    pub fn bond(&mut self, name: &str, from: &str, to: &str) -> &mut Self {
        self.bonds
            .push((name.to_owned(), from.to_owned(), to.to_owned()));
        self
    }
    /// Expose the member port `inner` as `name`.
    pub fn port(&mut self, name: &str, inner: &str) -> &mut Self {
        self.ports.push((name.to_owned(), inner.to_owned()));
        self
    }

    /// Rename everything into the global names of `instance` ([`member_name`]); exposed
    /// ports keep their names.
    #[must_use]
    pub fn expand(self, instance: &str) -> Expanded {
        Expanded {
            elements: self
                .elements
                .into_iter()
                .map(|(n, e)| (member_name(instance, &n), e))
                .collect(),
            bonds: self
                .bonds
                .iter()
                .map(|(n, a, b)| {
                    (
                        member_name(instance, n),
                        member_end(instance, a),
                        member_end(instance, b),
                    )
                })
                .collect(),
            ports: self
                .ports
                .into_iter()
                .map(|(n, inner)| {
                    let g = member_end(instance, &inner);
                    (n, g)
                })
                .collect(),
        }
    }

    /// Add the expanded composite to `graph`: members and internal bonds. Returns the exposed
    /// ports (name → global member port).
    pub fn add_to(
        self,
        instance: &str,
        graph: &mut crate::BondGraph,
    ) -> Result<Vec<(String, String)>, crate::Error> {
        let x = self.expand(instance);
        for (name, e) in x.elements {
            graph.add_boxed(&name, e)?;
        }
        for (name, from, to) in &x.bonds {
            graph.connect_ends(name, from, to)?;
        }
        Ok(x.ports)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Capacitor, OneJunction};

    #[test]
    fn expansion_names_members_and_keeps_port_names() {
        let mut c = Composite::default();
        c.element("j", OneJunction)
            .element("spring", Capacitor::new(1.0, 0.0).unwrap())
            .bond("b", "j", "spring")
            .port("mech", "j")
            .port("tip", "spring.p");
        let x = c.expand("arm");
        let names: Vec<&str> = x.elements.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["arm_j", "arm_spring"]);
        assert_eq!(
            x.bonds,
            [("arm_b".into(), "arm_j".into(), "arm_spring".into())]
        );
        assert_eq!(
            x.ports,
            [
                ("mech".into(), "arm_j".into()),
                ("tip".into(), "arm_spring.p".into())
            ]
        );
    }
}
