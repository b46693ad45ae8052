//! Data files: a CSV with a header row and numeric cells, as the inputs of a run
//! (`bg-sim run MODEL --inputs DATA.csv`, `[inputs] F = { file = …, column = … }`) and the
//! tables of a model (`[tables] eta = { file = … }`).
//!
//! Every problem is a [`ModelError`] naming the data file, the line (1-based, the header is
//! line 1) and the column (1-based character position of the cell), with a hint: a
//! non-numeric or empty cell, a row with too many or too few cells, unsorted or repeated
//! times, a column that names no input ("did you mean"), data that does not cover the run.

use std::path::Path;

use bondgraph::{Interp, Series};

use crate::error::{clip, ErrorKind, ModelError};

/// Largest data file read, in bytes.
pub const MAX_DATA_BYTES: usize = 256 << 20;

/// A CSV read: the header's names and, per column, its values (one per data row), with the
/// line and character column of each cell for errors.
#[derive(Clone, Debug)]
pub struct DataFile {
    /// The file, as named in errors.
    pub file: String,
    /// Column names, from the header.
    pub names: Vec<String>,
    /// Values per column.
    pub columns: Vec<Vec<f64>>,
    /// The 1-based line of each data row.
    pub lines: Vec<usize>,
    /// The 1-based character column where each header cell starts.
    pub starts: Vec<usize>,
}

fn err(file: &str, line: usize, col: usize, message: impl Into<String>) -> ModelError {
    ModelError::new(ErrorKind::Data, file, message).at(Some((line, col)))
}

impl DataFile {
    /// Read `path` (named `file` in errors).
    ///
    /// # Errors
    /// A [`ModelError`] at the file, line and column of the first bad cell.
    pub fn read(path: &Path, file: &str) -> Result<Self, ModelError> {
        use std::io::Read;
        let mut bytes = Vec::new();
        std::fs::File::open(path)
            .and_then(|f| f.take(MAX_DATA_BYTES as u64 + 1).read_to_end(&mut bytes))
            .map_err(|e| {
                ModelError::new(
                    ErrorKind::Io,
                    file,
                    format!("cannot read the data file: {e}"),
                )
                .hint("check the path (a path in a model file is relative to the model)")
            })?;
        if bytes.len() > MAX_DATA_BYTES {
            return Err(ModelError::new(
                ErrorKind::Io,
                file,
                format!("is larger than {} MiB", MAX_DATA_BYTES >> 20),
            ));
        }
        let text = String::from_utf8(bytes).map_err(|_| {
            ModelError::new(ErrorKind::Data, file, "is not UTF-8 text").hint("save it as a CSV")
        })?;
        Self::parse(&text, file)
    }

    /// Parse CSV `text` (named `file` in errors). Lines that are empty or start with `#` are
    /// skipped; cells are separated by commas and may be padded with spaces.
    ///
    /// # Errors
    /// A [`ModelError`] at the line and column of the first bad cell.
    pub fn parse(text: &str, file: &str) -> Result<Self, ModelError> {
        // a byte-order mark before the header (spreadsheets write one) is not a name
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut rows = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.trim_end_matches('\r')))
            .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
        let Some((hline, header)) = rows.next() else {
            return Err(ModelError::new(ErrorKind::Data, file, "has no header row")
                .hint("the first line names the columns: `t,F`"));
        };
        let cells = split(header);
        let names: Vec<String> = cells.iter().map(|(_, c)| c.trim().to_owned()).collect();
        let starts: Vec<usize> = cells.iter().map(|(s, _)| *s).collect();
        for (k, n) in names.iter().enumerate() {
            if n.is_empty() {
                return Err(err(
                    file,
                    hline,
                    starts[k],
                    format!("header cell {} is empty", k + 1),
                )
                .hint("name every column"));
            }
            if names[..k].contains(n) {
                return Err(err(
                    file,
                    hline,
                    starts[k],
                    format!("column `{}` appears twice in the header", clip(n)),
                ));
            }
        }
        let mut columns = vec![Vec::new(); names.len()];
        let mut lines = Vec::new();
        for (line, row) in rows {
            let cells = split(row);
            if cells.len() != names.len() {
                let col = cells
                    .get(names.len())
                    .map_or(row.chars().count() + 1, |c| c.0);
                return Err(err(
                    file,
                    line,
                    col,
                    format!("row has {} cells, the header {}", cells.len(), names.len()),
                )
                .hint("every row has one cell per column, separated by commas"));
            }
            for (k, (start, cell)) in cells.iter().enumerate() {
                let c = cell.trim();
                let v: f64 = c.parse().map_err(|_| {
                    err(
                        file,
                        line,
                        *start,
                        format!(
                            "cell `{}` of column `{}` is not a number",
                            clip(c),
                            names[k]
                        ),
                    )
                    .hint("cells are numbers such as 0.5, -3 or 1e-3")
                })?;
                if !v.is_finite() {
                    return Err(err(
                        file,
                        line,
                        *start,
                        format!("cell `{}` of column `{}` is not finite", clip(c), names[k]),
                    )
                    .hint("fill the gap in the data (NaN and infinities are refused)"));
                }
                columns[k].push(v);
            }
            lines.push(line);
        }
        if lines.is_empty() {
            return Err(err(file, hline, 1, "has a header but no data rows"));
        }
        Ok(Self {
            file: file.to_owned(),
            names,
            columns,
            lines,
            starts,
        })
    }

    /// The index of column `name`.
    #[must_use]
    pub fn column(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// The time column `t` (or `time`), checked strictly increasing.
    ///
    /// # Errors
    /// No time column, or the first time that is not after the one before, at its line.
    pub fn times(&self) -> Result<&[f64], ModelError> {
        let k = self
            .column("t")
            .or_else(|| self.column("time"))
            .ok_or_else(|| {
                err(&self.file, 1, 1, "has no time column `t`").hint(format!(
                    "name the time column `t`; the columns are: {}",
                    self.names.join(", ")
                ))
            })?;
        let t = &self.columns[k];
        for i in 1..t.len() {
            if t[i] <= t[i - 1] {
                let what = if t[i] < t[i - 1] {
                    "is before"
                } else {
                    "repeats"
                };
                return Err(err(
                    &self.file,
                    self.lines[i],
                    1,
                    format!(
                        "time {} {what} the time on the row before ({}): times must increase strictly",
                        t[i],
                        t[i - 1]
                    ),
                )
                .hint("sort the rows by time and remove repeated times"));
            }
        }
        Ok(t)
    }

    /// Column `k` as a series over the time column.
    ///
    /// # Errors
    /// As [`times`](Self::times).
    pub fn series(&self, k: usize, interp: Interp) -> Result<Series, ModelError> {
        let t = self.times()?.to_vec();
        Series::new(t, self.columns[k].clone(), interp)
            .map_err(|e| ModelError::new(ErrorKind::Data, &self.file, e.to_string()))
    }

    /// Check the time column covers `[t_start, t_end]`, saying which end it misses.
    ///
    /// # Errors
    /// The end not covered, with the hint to extend the data or ask for `extrapolate = "hold"`.
    pub fn covers(&self, t_start: f64, t_end: f64, what: &str) -> Result<(), ModelError> {
        let t = self.times()?;
        let (first, last) = (t[0], t[t.len() - 1]);
        let tol = 1e-10 * (1.0 + t_start.abs().max(t_end.abs()));
        if first > t_start + tol {
            return Err(err(
                &self.file,
                self.lines[0],
                1,
                format!("{what} starts at t = {first} s, after the run's start t_start = {t_start} s"),
            )
            .hint("add a row at the start, or let the first value hold before it (`extrapolate = \"hold\"`, `--inputs-extrapolate hold`)"));
        }
        if last < t_end - tol {
            return Err(err(
                &self.file,
                self.lines[self.lines.len() - 1],
                1,
                format!("{what} ends at t = {last} s, before the run's end t_end = {t_end} s"),
            )
            .hint("add rows up to t_end, shorten the run (--t-end), or let the last value hold (`extrapolate = \"hold\"`, `--inputs-extrapolate hold`)"));
        }
        Ok(())
    }
}

/// The cells of a CSV row with the 1-based character column where each starts.
fn split(row: &str) -> Vec<(usize, &str)> {
    let mut out = Vec::new();
    let mut start = 0;
    for (i, c) in row.char_indices() {
        if c == ',' {
            out.push((col_of(row, start), &row[start..i]));
            start = i + 1;
        }
    }
    out.push((col_of(row, start), &row[start..]));
    out
}

/// The 1-based character column of byte `b` of `row`, past leading spaces of the cell.
fn col_of(row: &str, b: usize) -> usize {
    let pad = row[b..].chars().take_while(|c| *c == ' ').count();
    row[..b].chars().count() + pad + 1
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn reads_columns_and_names_bad_cells_by_line_and_column() {
        let d = DataFile::parse("# a comment\nt, F\n0, 1\n1, 2.5\n", "d.csv").unwrap();
        assert_eq!(d.names, ["t", "F"]);
        assert_eq!(d.columns[1], [1.0, 2.5]);
        assert_eq!(d.lines, [3, 4]);
        let e = DataFile::parse("t,F\n0,1\n1,x\n", "d.csv").unwrap_err();
        assert_eq!((e.line, e.col), (Some(3), Some(3)), "{e}");
        assert!(e.message.contains("not a number"), "{e}");
        let e = DataFile::parse("t,F\n0,1\n1\n", "d.csv").unwrap_err();
        assert!(e.message.contains("1 cells"), "{e}");
        let e = DataFile::parse("t,F\n0,1\n0,2\n", "d.csv")
            .unwrap()
            .times()
            .unwrap_err();
        assert_eq!(e.line, Some(3));
        assert!(e.message.contains("repeats"), "{e}");
        let e = DataFile::parse("t,F\n0,1\n2,1\n", "d.csv")
            .unwrap()
            .covers(0.0, 3.0, "F")
            .unwrap_err();
        assert!(e.message.contains("before the run's end"), "{e}");
        let e = DataFile::parse("t,F\n0,nan\n", "d.csv").unwrap_err();
        assert!(e.message.contains("not finite"), "{e}");
    }
}
