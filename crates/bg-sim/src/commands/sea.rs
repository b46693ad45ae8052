//! `bg-sim sea`: an irregular sea state as a time series (docs/sea-states.md): the wave
//! elevation at the vessel's reference point and, with an RAO table, the vessel's heave,
//! sway and roll at a point (the crane pedestal); `--plot` draws the record and its
//! estimated spectrum against the target spectrum.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use bg_ocean::{analysis, Dof, Point, Rao, Spectrum, VesselMotion, WaveRecord};

use super::{BAD_INPUT, FAILED};

/// The options of `bg-sim sea` (its summary is on `Command::Sea` in main.rs).
#[derive(clap::Args)]
pub struct Args {
    /// Significant wave height Hs [m].
    #[arg(long)]
    pub hs: f64,
    /// Peak period Tp [s].
    #[arg(long)]
    pub tp: f64,
    /// JONSWAP peak enhancement γ.
    #[arg(long, default_value_t = 3.3)]
    pub gamma: f64,
    /// The spectrum: `jonswap` or `pm` (Pierson–Moskowitz).
    #[arg(long, default_value = "jonswap")]
    pub spectrum: String,
    /// RAO table (CSV, docs/sea-states.md): adds heave, sway and roll columns.
    #[arg(long)]
    pub rao: Option<PathBuf>,
    /// Wave heading [deg] (0 following sea, 90 beam sea, 180 head sea).
    #[arg(long, default_value_t = 0.0)]
    pub heading: f64,
    /// The point whose motion is written, `X,Y,Z` [m] from the RAO's reference point.
    #[arg(long, default_value = "0,0,0")]
    pub point: String,
    /// Length of the record [s].
    #[arg(long, default_value_t = 1800.0)]
    pub duration: f64,
    /// Sampling step [s].
    #[arg(long, default_value_t = 0.05)]
    pub dt: f64,
    /// Seed of the random phases and frequencies (the same seed, the same record).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Output CSV (columns t, eta[, heave, sway, roll]).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Draw the record (its first 300 s) and its spectrum against the target as a PNG here.
    #[arg(long)]
    pub plot: Option<PathBuf>,
}

fn bad(message: &str, hint: &str) -> ExitCode {
    tell!("error: {message}\n  hint: {hint}");
    ExitCode::from(BAD_INPUT)
}

/// `bg-sim sea`.
pub fn command(a: &Args) -> ExitCode {
    let spectrum = match a.spectrum.as_str() {
        "jonswap" => Spectrum::jonswap(a.hs, a.tp, a.gamma),
        "pm" => Spectrum::pierson_moskowitz(a.hs, a.tp),
        s => {
            return bad(
                &format!("--spectrum `{s}` is not a spectrum"),
                "--spectrum jonswap (the default) or --spectrum pm",
            )
        }
    };
    let spectrum = match spectrum {
        Ok(s) => s,
        Err(e) => return bad(&e.message, &e.hint),
    };
    let point: Vec<f64> = a
        .point
        .split(',')
        .filter_map(|v| v.trim().parse().ok())
        .collect();
    if point.len() != 3 || point.iter().any(|v: &f64| !v.is_finite()) {
        return bad(
            &format!("--point `{}` is not X,Y,Z", a.point),
            "--point 5,-8,12 (metres)",
        );
    }
    let point = Point {
        x: point[0],
        y: point[1],
        z: point[2],
    };
    if !(a.duration.is_finite() && a.duration > 0.0 && a.duration / a.dt <= 1e8) {
        return bad(
            &format!("--duration {} s at --dt {} s", a.duration, a.dt),
            "a positive duration of at most 1e8 steps",
        );
    }
    let record = match WaveRecord::irregular(spectrum, a.duration, a.dt, a.seed) {
        Ok(r) => r,
        Err(e) => return bad(&e.message, &e.hint),
    };
    let motion = match &a.rao {
        None => None,
        Some(path) => match Rao::read(path) {
            Ok(rao) => Some(VesselMotion::new(&record, &rao, a.heading, point)),
            Err(e) => {
                let at = e.line.map(|l| format!(":{l}")).unwrap_or_default();
                return bad(
                    &format!("{}{at}: {}", path.display(), e.message),
                    if e.hint.is_empty() {
                        "docs/sea-states.md describes the RAO file"
                    } else {
                        &e.hint
                    },
                );
            }
        },
    };
    let n = (a.duration / a.dt).round() as usize + 1;
    let dofs = [Dof::Heave, Dof::Sway, Dof::Roll];
    let mut eta = Vec::with_capacity(n);
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); if motion.is_some() { 3 } else { 0 }];
    for k in 0..n {
        let t = k as f64 * a.dt;
        eta.push(record.eval(t).0);
        if let Some(m) = &motion {
            for (c, d) in cols.iter_mut().zip(dofs) {
                c.push(m.eval(d, t).0);
            }
        }
    }
    let mut text = String::from(if motion.is_some() {
        "t,eta,heave,sway,roll\n"
    } else {
        "t,eta\n"
    });
    for k in 0..n {
        text.push_str(&format!("{},{}", k as f64 * a.dt, eta[k]));
        for c in &cols {
            text.push_str(&format!(",{}", c[k]));
        }
        text.push('\n');
    }
    let written = std::fs::File::create(&a.output).and_then(|mut f| f.write_all(text.as_bytes()));
    if let Err(e) = written {
        tell!("error: cannot write {}: {e}", a.output.display());
        return ExitCode::from(FAILED);
    }
    let hs = 4.0 * analysis::std(&eta);
    let tp = analysis::peak_period(&eta, a.dt);
    say!(
        "{}: {} components, {} rows; 4·std(η) = {hs:.4} m (Hs {} m), spectral peak {tp:.3} s (Tp {} s)",
        a.output.display(),
        record.harmonics().components().len(),
        n,
        a.hs,
        a.tp
    );
    if let Some(path) = &a.plot {
        let (w, s) = analysis::welch(&eta, a.dt);
        let w1 = 4.0 * spectrum.omega_p();
        let tw: Vec<f64> = (0..=400).map(|k| w1 * f64::from(k) / 400.0).collect();
        let ts: Vec<f64> = tw.iter().map(|&x| spectrum.density(x)).collect();
        let names = ["heave [m]", "sway [m]", "roll [deg]"];
        let roll_deg: Vec<f64> = cols
            .get(2)
            .map_or_else(Vec::new, |r| r.iter().map(|v| v.to_degrees()).collect());
        let mut series = vec![bg_sim::plot::SeaSeries {
            name: "η [m]",
            values: &eta,
        }];
        for (k, (c, name)) in cols.iter().zip(names).enumerate() {
            let values = if k == 2 { &roll_deg } else { c };
            series.push(bg_sim::plot::SeaSeries { name, values });
        }
        let kind = if a.spectrum == "pm" {
            "Pierson–Moskowitz".to_owned()
        } else {
            format!("JONSWAP γ {}", a.gamma)
        };
        let window = a.duration.min(300.0);
        let title = format!(
            "{kind}, Hs {} m, Tp {} s, seed {} (record: first {window} s)",
            a.hs, a.tp, a.seed
        );
        match bg_sim::plot::sea_figure(&title, &series, a.dt, window, (&w, &s), (&tw, &ts), path) {
            Ok(p) => say!("{}", p.display()),
            Err(e) => {
                tell!("error: {e}");
                return ExitCode::from(FAILED);
            }
        }
    }
    ExitCode::SUCCESS
}
