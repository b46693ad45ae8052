//! Response amplitude operators: the vessel's linear response per metre of wave amplitude,
//! per frequency and wave heading, read from a CSV.
//!
//! ## The file
//!
//! Lines starting with `#` are comments; blank lines are skipped. The first other line is
//! the header, naming these eight columns (in any order; the names are the units):
//!
//! | column | meaning |
//! |---|---|
//! | `heading_deg` | wave heading β [deg], in [0, 360): the angle from the vessel's bow (+x) to the direction the waves travel, anticlockwise seen from above (0 following sea, 90 beam sea travelling to port, 180 head sea) |
//! | `omega_rad_s` | wave angular frequency ω [rad/s] |
//! | `heave_amp_m_per_m`, `heave_phase_deg` | heave per metre of wave amplitude [m/m], its phase [deg] |
//! | `sway_amp_m_per_m`, `sway_phase_deg` | sway [m/m], phase [deg] |
//! | `roll_amp_deg_per_m`, `roll_phase_deg` | roll [deg/m] (read into rad/m), phase [deg] |
//!
//! A phase θ is the lead of the motion over the wave elevation at the vessel's motion
//! reference point: a regular wave η = a·cos(ωt + φ) gives heave = a·|H|·cos(ωt + φ + θ).
//! Rows are grouped by heading; inside a heading the frequencies increase strictly, and
//! every heading lists the same frequencies.
//!
//! ## Interpolation
//!
//! Between tabulated frequencies and headings: linear in amplitude and in phase (the phase
//! step taken the short way round, within ±180°), bilinear over (ω, β); headings are
//! periodic over 360°. Beyond the first or last frequency the end values hold (a table
//! should reach low enough for heave → 1 and high enough for the response → 0). One
//! heading alone serves every heading.

use std::path::Path;

use crate::OceanError;

/// A degree of freedom of the vessel (or the wave itself).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dof {
    /// The wave elevation η [m] at the reference point.
    Elevation,
    /// Heave [m], up.
    Heave,
    /// Sway [m], along the vessel's y (to port).
    Sway,
    /// Roll [rad], right-handed about the vessel's x (bow).
    Roll,
}

impl Dof {
    /// Parse `elevation` (`eta`), `heave`, `sway`, `roll`.
    #[must_use]
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "elevation" | "eta" => Some(Self::Elevation),
            "heave" => Some(Self::Heave),
            "sway" => Some(Self::Sway),
            "roll" => Some(Self::Roll),
            _ => None,
        }
    }
    /// The name `parse` accepts.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Elevation => "elevation",
            Self::Heave => "heave",
            Self::Sway => "sway",
            Self::Roll => "roll",
        }
    }
}

/// The header's column names, in the order the values are stored.
pub const COLUMNS: [&str; 8] = [
    "heading_deg",
    "omega_rad_s",
    "heave_amp_m_per_m",
    "heave_phase_deg",
    "sway_amp_m_per_m",
    "sway_phase_deg",
    "roll_amp_deg_per_m",
    "roll_phase_deg",
];

/// An RAO table (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct Rao {
    headings: Vec<f64>,
    omegas: Vec<f64>,
    /// Per heading h and frequency j, at `h·n_ω + j`: (amplitude, phase [rad]) of heave,
    /// sway, roll (roll amplitude in rad/m).
    values: Vec<[(f64, f64); 3]>,
}

fn wrap_deg(d: f64) -> f64 {
    let w = (d + 180.0).rem_euclid(360.0) - 180.0;
    if w == -180.0 {
        180.0
    } else {
        w
    }
}

impl Rao {
    /// Read an RAO CSV file.
    ///
    /// # Errors
    /// The file cannot be read, or [`Rao::parse`] refuses it.
    pub fn read(path: &Path) -> Result<Self, OceanError> {
        let text = std::fs::read_to_string(path).map_err(|e| {
            OceanError::new(format!("cannot read {}: {e}", path.display()))
                .hint("give the RAO file's path relative to the model file or the working directory")
        })?;
        Self::parse(&text)
    }

    /// Parse the text of an RAO CSV (see the module documentation).
    ///
    /// # Errors
    /// [`OceanError`] at the line: a missing or unknown column, a bad number, a negative
    /// amplitude, a heading outside [0, 360), frequencies not increasing or differing
    /// between headings, no rows.
    pub fn parse(text: &str) -> Result<Self, OceanError> {
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(k, l)| (k + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
        let (hline, header) = lines.next().ok_or_else(|| {
            OceanError::new("the RAO file has no header").hint(format!("the header names the columns {}", COLUMNS.join(",")))
        })?;
        let names: Vec<&str> = header.split(',').map(str::trim).collect();
        let mut index = [0usize; 8];
        for (c, col) in COLUMNS.iter().enumerate() {
            index[c] = names.iter().position(|n| n == col).ok_or_else(|| {
                OceanError::at(hline, format!("the header has no column `{col}`"))
                    .hint(format!("the columns are {}", COLUMNS.join(",")))
            })?;
        }
        if let Some(extra) = names.iter().find(|n| !COLUMNS.contains(n)) {
            return Err(OceanError::at(hline, format!("unknown column `{extra}`"))
                .hint(format!("the columns are {}", COLUMNS.join(","))));
        }
        let mut headings: Vec<f64> = Vec::new();
        let mut omegas: Vec<f64> = Vec::new();
        let mut values = Vec::new();
        let mut j = 0; // frequency index within the current heading
        for (line, l) in lines {
            let cells: Vec<&str> = l.split(',').map(str::trim).collect();
            if cells.len() != names.len() {
                return Err(OceanError::at(
                    line,
                    format!("{} cells, the header has {}", cells.len(), names.len()),
                ));
            }
            let mut v = [0.0; 8];
            for c in 0..8 {
                let s = cells[index[c]];
                v[c] = s.parse::<f64>().ok().filter(|x| x.is_finite()).ok_or_else(|| {
                    OceanError::at(line, format!("`{s}` in column `{}` is not a number", COLUMNS[c]))
                })?;
            }
            let (h, w) = (v[0], v[1]);
            if !(0.0..360.0).contains(&h) {
                return Err(OceanError::at(line, format!("heading {h} is outside [0, 360)")));
            }
            if w <= 0.0 {
                return Err(OceanError::at(line, format!("frequency {w} rad/s is not positive")));
            }
            for c in [2, 4, 6] {
                if v[c] < 0.0 {
                    return Err(OceanError::at(line, format!("amplitude `{}` = {} is negative", COLUMNS[c], v[c]))
                        .hint("put the sign in the phase (a negative amplitude is a phase of 180°)"));
                }
            }
            if headings.last() != Some(&h) {
                if let Some(&last) = headings.last() {
                    if h <= last {
                        return Err(OceanError::at(line, format!("heading {h} after {last}: headings must increase")));
                    }
                    if j != omegas.len() {
                        return Err(OceanError::at(line, format!("heading {last} has {j} frequencies, the first heading {}", omegas.len())));
                    }
                }
                headings.push(h);
                j = 0;
            }
            if headings.len() == 1 {
                if let Some(&last) = omegas.last() {
                    if w <= last {
                        return Err(OceanError::at(line, format!("frequency {w} after {last}: frequencies must increase within a heading")));
                    }
                }
                omegas.push(w);
            } else if omegas.get(j) != Some(&w) {
                return Err(OceanError::at(line, format!("frequency {w} where the first heading has {}", omegas.get(j).map_or("no more".to_owned(), f64::to_string)))
                    .hint("every heading lists the same frequencies"));
            }
            values.push([
                (v[2], v[3].to_radians()),
                (v[4], v[5].to_radians()),
                (v[6].to_radians(), v[7].to_radians()),
            ]);
            j += 1;
        }
        if headings.is_empty() {
            return Err(OceanError::new("the RAO file has no rows"));
        }
        if j != omegas.len() {
            return Err(OceanError::new(format!("the last heading has {j} frequencies, the first {}", omegas.len())));
        }
        Ok(Self {
            headings,
            omegas,
            values,
        })
    }

    /// The tabulated headings [deg].
    #[must_use]
    pub fn headings(&self) -> &[f64] {
        &self.headings
    }
    /// The tabulated frequencies [rad/s].
    #[must_use]
    pub fn omegas(&self) -> &[f64] {
        &self.omegas
    }

    /// (amplitude, phase [rad]) of `dof` at frequency `omega` [rad/s] and heading
    /// `heading` [deg], interpolated (see the module documentation). Roll in rad per metre;
    /// the elevation is (1, 0).
    #[must_use]
    pub fn at(&self, dof: Dof, omega: f64, heading: f64) -> (f64, f64) {
        let d = match dof {
            Dof::Elevation => return (1.0, 0.0),
            Dof::Heave => 0,
            Dof::Sway => 1,
            Dof::Roll => 2,
        };
        let nw = self.omegas.len();
        // frequency: index pair and weight
        let (j0, j1, fw) = bracket(&self.omegas, omega);
        // heading: periodic
        let nh = self.headings.len();
        let b = heading.rem_euclid(360.0);
        let (h0, h1, fh) = if nh == 1 {
            (0, 0, 0.0)
        } else {
            let k = self.headings.partition_point(|&h| h <= b);
            let (h0, h1) = if k == 0 || k == nh { (nh - 1, 0) } else { (k - 1, k) };
            let span = (self.headings[h1] - self.headings[h0]).rem_euclid(360.0);
            let from = (b - self.headings[h0]).rem_euclid(360.0);
            (h0, h1, if span > 0.0 { from / span } else { 0.0 })
        };
        let pick = |h: usize, j: usize| self.values[h * nw + j][d];
        let lerp = |a: (f64, f64), c: (f64, f64), f: f64| {
            let step = wrap_deg((c.1 - a.1).to_degrees()).to_radians();
            (a.0 + f * (c.0 - a.0), a.1 + f * step)
        };
        let lo = lerp(pick(h0, j0), pick(h0, j1), fw);
        let hi = lerp(pick(h1, j0), pick(h1, j1), fw);
        lerp(lo, hi, fh)
    }
}

/// Indices (j0, j1) and weight of `x` in the increasing `xs`, holding the ends.
fn bracket(xs: &[f64], x: f64) -> (usize, usize, f64) {
    let n = xs.len();
    if n == 1 || x <= xs[0] {
        return (0, 0, 0.0);
    }
    if x >= xs[n - 1] {
        return (n - 1, n - 1, 0.0);
    }
    let k = xs.partition_point(|&v| v <= x);
    (k - 1, k, (x - xs[k - 1]) / (xs[k] - xs[k - 1]))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::float_cmp)]
    use super::*;

    const TABLE: &str = "# a test table\n\
heading_deg,omega_rad_s,heave_amp_m_per_m,heave_phase_deg,sway_amp_m_per_m,sway_phase_deg,roll_amp_deg_per_m,roll_phase_deg\n\
0,0.5,1.0,0,0.1,90,1,-90\n\
0,1.0,0.5,-30,0.2,80,3,-100\n\
90,0.5,1.0,10,0.8,90,4,170\n\
90,1.0,0.3,-50,0.6,100,8,-170\n";

    #[test]
    fn tabulated_points_are_returned_and_between_them_it_interpolates() {
        let r = Rao::parse(TABLE).unwrap();
        let (a, p) = r.at(Dof::Heave, 1.0, 0.0);
        assert!((a - 0.5).abs() < 1e-15 && (p - (-30f64).to_radians()).abs() < 1e-15);
        let (a, p) = r.at(Dof::Heave, 0.75, 45.0);
        assert!((a - (0.75 + 0.65) / 2.0).abs() < 1e-12);
        assert!((p.to_degrees() - (-15.0 - 20.0) / 2.0).abs() < 1e-12);
        // roll in rad/m; the phase from 170 to −170 goes the short way (through 180)
        let (a, p) = r.at(Dof::Roll, 0.75, 90.0);
        assert!((a - 6f64.to_radians()).abs() < 1e-12);
        assert!((wrap_deg(p.to_degrees()) - 180.0).abs() < 1e-9, "{}", p.to_degrees());
        // beyond the frequencies the ends hold; headings are periodic (315 between 90 and 360=0)
        assert_eq!(r.at(Dof::Sway, 5.0, 0.0).0, 0.2);
        let (a, _) = r.at(Dof::Sway, 0.5, 315.0);
        assert!((a - (0.8 + (0.1 - 0.8) * 225.0 / 270.0)).abs() < 1e-12);
    }

    #[test]
    fn bad_tables_are_refused_at_their_line() {
        let bad = TABLE.replace("0,1.0,0.5,-30", "0,0.4,0.5,-30");
        let e = Rao::parse(&bad).unwrap_err();
        assert_eq!(e.line, Some(4), "{e}");
        let e = Rao::parse(&TABLE.replace("heave_amp_m_per_m", "heave")).unwrap_err();
        assert_eq!(e.line, Some(2));
        assert!(e.message.contains("heave_amp_m_per_m"), "{e}");
        let e = Rao::parse(&TABLE.replace("90,1.0,0.3", "90,1.1,0.3")).unwrap_err();
        assert_eq!(e.line, Some(6));
        let e = Rao::parse(&TABLE.replace("0.3,-50", "-0.3,-50")).unwrap_err();
        assert!(e.message.contains("negative"));
        assert!(Rao::parse("# nothing\n").is_err());
    }
}
