//! A results CSV read back ([`Results`]): named columns of equal length, `t` first.

use std::path::Path;

use super::PlotError;

/// A results table: named columns of equal length, the first one `t`, at least one row
/// (made only by [`Results::read`] and [`Results::parse`], which check that).
#[derive(Clone, Debug)]
pub struct Results {
    names: Vec<String>,
    columns: Vec<Vec<f64>>,
}

impl Results {
    /// Read a CSV written by `bg-sim run`: a header of column names, then rows of numbers.
    pub fn read(path: &Path) -> Result<Self, PlotError> {
        let text = std::fs::read_to_string(path).map_err(|source| PlotError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(&text).map_err(|(line, message)| PlotError::Format {
            path: path.to_path_buf(),
            line,
            message,
        })
    }

    /// Parse CSV text; errors carry the 1-based line.
    pub fn parse(text: &str) -> Result<Self, (usize, String)> {
        let mut lines = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty());
        let (_, header) = lines
            .next()
            .ok_or_else(|| (1, "empty file: expected a header line".to_owned()))?;
        let names: Vec<String> = header.split(',').map(|s| s.trim().to_owned()).collect();
        if names.first().map(String::as_str) != Some("t") {
            return Err((1, "the first column must be `t`".to_owned()));
        }
        let mut columns = vec![Vec::new(); names.len()];
        for (i, line) in lines {
            let cells: Vec<&str> = line.split(',').collect();
            if cells.len() != names.len() {
                return Err((
                    i + 1,
                    format!("{} values, the header has {}", cells.len(), names.len()),
                ));
            }
            for (c, cell) in cells.iter().enumerate() {
                let v: f64 = cell
                    .trim()
                    .parse()
                    .map_err(|_| (i + 1, format!("`{cell}` is not a number")))?;
                columns[c].push(v);
            }
        }
        if columns[0].is_empty() {
            return Err((2, "no rows".to_owned()));
        }
        Ok(Self { names, columns })
    }

    /// The column called `name`.
    #[must_use]
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|i| self.columns[i].as_slice())
    }

    /// The column names, `t` first.
    #[must_use]
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The table as a [`Trajectory`](bondgraph::Trajectory) (rows of values, `t` first).
    #[must_use]
    pub fn to_trajectory(&self) -> bondgraph::Trajectory {
        let n = self.columns[0].len();
        bondgraph::Trajectory {
            columns: self.names.clone(),
            rows: (0..n)
                .map(|i| self.columns.iter().map(|c| c[i]).collect())
                .collect(),
        }
    }

    /// The time column.
    #[must_use]
    pub fn time(&self) -> &[f64] {
        &self.columns[0]
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn parse_reads_columns_and_names_bad_lines() {
        let r = Results::parse("t,a\n0,1\n0.5,2\n").unwrap();
        assert_eq!(r.column("a"), Some(&[1.0, 2.0][..]));
        assert_eq!(r.time(), &[0.0, 0.5]);
        assert!(r.column("b").is_none());
        assert_eq!(Results::parse("t,a\n0,x\n").err().map(|e| e.0), Some(2));
        assert_eq!(Results::parse("t,a\n0\n").err().map(|e| e.0), Some(2));
        assert_eq!(Results::parse("x,a\n0,1\n").err().map(|e| e.0), Some(1));
        assert!(Results::parse("").is_err());
        assert!(Results::parse("t\n").is_err());
    }
}
