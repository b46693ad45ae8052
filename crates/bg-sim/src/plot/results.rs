//! A results CSV read back ([`Results`]): named columns of equal length, `t` first.
//!
//! The file is read line by line, never whole (a 300 MB CSV was held as text beside its
//! numbers). For a figure, [`Results::read_for_plot`] keeps only the columns drawn and at
//! most about [`PLOT_ROWS`] rows of them: beyond that the rows are decimated in buckets of
//! consecutive rows, each bucket keeping its first and last row and, for every kept column,
//! the row of its smallest and of its largest value — so every curve keeps its envelope (no
//! peak is lost) and every kept point is a whole row (a curve of one column against another
//! stays on the data). Memory is then bounded by the columns drawn, not by the file.

use std::io::BufRead;
use std::path::Path;

use super::PlotError;

/// Rows [`Results::read_for_plot`] keeps at most (or `2 + 2·columns`, if more): beyond it,
/// buckets of 2, 4, 8, … rows keep their first, last, smallest and largest values.
pub const PLOT_ROWS: usize = 100_000;

/// A results table: named columns of equal length, the first one `t`, at least one row
/// (made only by [`Results::read`], [`Results::read_for_plot`] and [`Results::parse`], which
/// check that). Every column of the header is named; all, or the ones asked for, are held.
#[derive(Clone, Debug)]
pub struct Results {
    names: Vec<String>,
    /// Per header column, its values if held.
    columns: Vec<Option<Vec<f64>>>,
    /// Data rows in the file (more than held if decimated).
    rows_read: usize,
    /// Rows per bucket of the decimation (1: every row held).
    bucket: usize,
}

/// Why a results text could not be read: the I/O, or a line and what is wrong with it.
enum Failure {
    Io(std::io::Error),
    Line(usize, String),
}

/// `path` is a FIFO, a socket, a directory or a device: what it is, so that it can be refused
/// before it is opened (a FIFO without a writer blocks `open` for ever). `None` for a regular
/// file, a path that does not exist (opening it says so), or a symbolic link to a regular file.
#[must_use]
pub fn not_a_regular_file(path: &Path) -> Option<&'static str> {
    let kind = std::fs::metadata(path).ok()?.file_type();
    if kind.is_file() {
        return None;
    }
    if kind.is_dir() {
        return Some("a directory");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return Some("a FIFO (named pipe)");
        }
        if kind.is_socket() {
            return Some("a socket");
        }
    }
    Some("a device")
}

impl Results {
    /// Read a CSV written by `bg-sim run`: a header of column names, then rows of numbers.
    /// Every row and column is held.
    pub fn read(path: &Path) -> Result<Self, PlotError> {
        Self::read_with(path, None, None)
    }

    /// Read a CSV for a figure: the header's names all, the values of `columns` (and `t`)
    /// only, at most about [`PLOT_ROWS`] rows of them (see the module's notes). Every cell is
    /// still checked. A file of at most [`PLOT_ROWS`] rows is held whole.
    pub fn read_for_plot(path: &Path, columns: &[&str]) -> Result<Self, PlotError> {
        Self::read_with(path, Some(columns), Some(PLOT_ROWS))
    }

    fn read_with(
        path: &Path,
        columns: Option<&[&str]>,
        max_rows: Option<usize>,
    ) -> Result<Self, PlotError> {
        let read = |source| PlotError::Read {
            path: path.to_path_buf(),
            source,
        };
        if let Some(what) = not_a_regular_file(path) {
            return Err(read(std::io::Error::other(format!(
                "it is {what}, not a results file (write piped data to a file first)"
            ))));
        }
        let file = std::fs::File::open(path).map_err(read)?;
        let reader = std::io::BufReader::with_capacity(1 << 16, file);
        Self::from_lines(reader, columns, max_rows).map_err(|f| match f {
            Failure::Io(source) => read(source),
            Failure::Line(line, message) => PlotError::Format {
                path: path.to_path_buf(),
                line,
                message,
            },
        })
    }

    /// Parse CSV text; errors carry the 1-based line. Every row and column is held.
    pub fn parse(text: &str) -> Result<Self, (usize, String)> {
        Self::from_lines(text.as_bytes(), None, None).map_err(|f| match f {
            Failure::Line(line, message) => (line, message),
            Failure::Io(e) => (1, e.to_string()),
        })
    }

    /// Parse a CSV line by line (lines as [`str::lines`] splits them, blank ones skipped),
    /// holding the values of `columns` (all if `None`), decimated beyond `max_rows`.
    fn from_lines(
        mut reader: impl BufRead,
        columns: Option<&[&str]>,
        max_rows: Option<usize>,
    ) -> Result<Self, Failure> {
        let mut buf = String::new();
        let mut number = 0usize;
        // the next non-blank line and its 1-based number
        let mut next = |buf: &mut String| -> Result<Option<usize>, Failure> {
            loop {
                buf.clear();
                if reader.read_line(buf).map_err(Failure::Io)? == 0 {
                    return Ok(None);
                }
                number += 1;
                if let Some(l) = buf.strip_suffix('\n') {
                    let l = l.strip_suffix('\r').unwrap_or(l).len();
                    buf.truncate(l);
                }
                if !buf.trim().is_empty() {
                    return Ok(Some(number));
                }
            }
        };
        if next(&mut buf)?.is_none() {
            return Err(Failure::Line(
                1,
                "empty file: expected a header line".to_owned(),
            ));
        }
        let names: Vec<String> = buf.split(',').map(|s| s.trim().to_owned()).collect();
        if names.first().map(String::as_str) != Some("t") {
            return Err(Failure::Line(1, "the first column must be `t`".to_owned()));
        }
        let held: Vec<bool> = names
            .iter()
            .enumerate()
            .map(|(i, n)| i == 0 || columns.is_none_or(|c| c.contains(&n.as_str())))
            .collect();
        let mut table = Decimated::new(held.iter().filter(|&&h| h).count(), max_rows);
        let mut row = Vec::with_capacity(names.len());
        while let Some(line) = next(&mut buf)? {
            let cells = buf.split(',').count();
            if cells != names.len() {
                return Err(Failure::Line(
                    line,
                    format!("{cells} values, the header has {}", names.len()),
                ));
            }
            row.clear();
            for (cell, &h) in buf.split(',').zip(&held) {
                let v: f64 = cell
                    .trim()
                    .parse()
                    .map_err(|_| Failure::Line(line, format!("`{cell}` is not a number")))?;
                if h {
                    row.push(v);
                }
            }
            table.push(&row);
        }
        if table.rows_read == 0 {
            return Err(Failure::Line(2, "no rows".to_owned()));
        }
        let (bucket, rows_read) = (table.bucket, table.rows_read);
        let mut values = table.finish().into_iter();
        let columns = held
            .iter()
            .map(|&h| if h { values.next() } else { None })
            .collect();
        Ok(Self {
            names,
            columns,
            rows_read,
            bucket,
        })
    }

    /// The column called `name`, if held.
    #[must_use]
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.names
            .iter()
            .position(|n| n == name)
            .and_then(|i| self.columns[i].as_deref())
    }

    /// The column names of the header, `t` first (held or not).
    #[must_use]
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Data rows in the file.
    #[must_use]
    pub fn rows_read(&self) -> usize {
        self.rows_read
    }

    /// Rows held: all of them, or fewer if [`read_for_plot`](Self::read_for_plot) decimated.
    #[must_use]
    pub fn rows_held(&self) -> usize {
        self.time().len()
    }

    /// Consecutive rows per bucket of the decimation (1: every row held).
    #[must_use]
    pub fn bucket(&self) -> usize {
        self.bucket
    }

    /// The held columns as a [`Trajectory`](bondgraph::Trajectory) (rows of values, `t`
    /// first).
    #[must_use]
    pub fn to_trajectory(&self) -> bondgraph::Trajectory {
        let held: Vec<(&String, &Vec<f64>)> = self
            .names
            .iter()
            .zip(&self.columns)
            .filter_map(|(n, c)| Some((n, c.as_ref()?)))
            .collect();
        bondgraph::Trajectory {
            columns: held.iter().map(|(n, _)| (*n).clone()).collect(),
            rows: (0..self.rows_held())
                .map(|i| held.iter().map(|(_, c)| c[i]).collect())
                .collect(),
        }
    }

    /// The time column.
    #[must_use]
    pub fn time(&self) -> &[f64] {
        self.columns[0].as_deref().unwrap_or(&[])
    }
}

/// Rows pushed one at a time and held as columns, decimated when more than `max` are held:
/// the bucket (consecutive rows of the file) doubles and each bucket keeps only its
/// [`envelope`] rows. Selecting again from what an earlier, finer selection kept gives
/// what the coarser selection of every row would (a bucket's first, last and extreme rows
/// are among those of its halves'), so the result does not depend on when it happened.
struct Decimated {
    /// Row of the file (0-based) of each held row.
    index: Vec<usize>,
    columns: Vec<Vec<f64>>,
    max: Option<usize>,
    bucket: usize,
    rows_read: usize,
}

impl Decimated {
    fn new(n: usize, max: Option<usize>) -> Self {
        Self {
            index: Vec::new(),
            columns: vec![Vec::new(); n],
            // a bucket holds up to 2 + 2n rows: a limit below twice that could not be met
            max: max.map(|m| m.max(4 * (n + 1))),
            bucket: 1,
            rows_read: 0,
        }
    }

    fn push(&mut self, row: &[f64]) {
        self.index.push(self.rows_read);
        for (c, &v) in self.columns.iter_mut().zip(row) {
            c.push(v);
        }
        self.rows_read += 1;
        if let Some(max) = self.max {
            // the rows since the last selection at the current bucket first, then coarser
            // until half the room is free again: amortised O(columns) per row
            if self.index.len() > max {
                self.select();
                while self.index.len() > max / 2 {
                    self.bucket *= 2;
                    self.select();
                }
            }
        }
    }

    /// Keep, of the held rows, each bucket's [`envelope`] rows.
    fn select(&mut self) {
        let mut keep = Vec::with_capacity(self.index.len());
        let mut start = 0;
        while start < self.index.len() {
            let b = self.index[start] / self.bucket;
            let end = start
                + self.index[start..]
                    .iter()
                    .take_while(|&&i| i / self.bucket == b)
                    .count();
            envelope(&self.columns, start, end, &mut keep);
            start = end;
        }
        let kept = |v: &[f64]| keep.iter().map(|&i| v[i]).collect::<Vec<f64>>();
        self.index = keep.iter().map(|&i| self.index[i]).collect();
        for c in &mut self.columns {
            *c = kept(c);
        }
    }

    /// The held columns; if decimated, each bucket reduced to its envelope rows (the last,
    /// partial bucket too), so that the result is the selection over every row.
    fn finish(mut self) -> Vec<Vec<f64>> {
        if self.bucket > 1 {
            self.select();
        }
        self.columns
    }
}

/// Push onto `keep`, in order, the rows `start..end` (of `columns`) that are the first, the
/// last, or the first to hold a column's smallest or largest finite value in that range.
fn envelope(columns: &[Vec<f64>], start: usize, end: usize, keep: &mut Vec<usize>) {
    let from = keep.len();
    keep.push(start);
    keep.push(end - 1);
    for c in columns {
        let mut lo: Option<usize> = None;
        let mut hi: Option<usize> = None;
        for i in start..end {
            let v = c[i];
            if !v.is_finite() {
                continue;
            }
            if lo.is_none_or(|l| v < c[l]) {
                lo = Some(i);
            }
            if hi.is_none_or(|h| v > c[h]) {
                hi = Some(i);
            }
        }
        keep.extend(lo);
        keep.extend(hi);
    }
    keep[from..].sort_unstable();
    let mut last = None;
    let mut w = from;
    for r in from..keep.len() {
        if Some(keep[r]) != last {
            last = Some(keep[r]);
            keep[w] = keep[r];
            w += 1;
        }
    }
    keep.truncate(w);
}

#[cfg(test)]
// values held are copies of the file's, compared exactly
#[allow(clippy::unwrap_used, clippy::float_cmp)]
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
        assert_eq!(Results::parse("t,a\n0,1,2\n").err().map(|e| e.0), Some(2));
        assert_eq!(Results::parse("x,a\n0,1\n").err().map(|e| e.0), Some(1));
        assert!(Results::parse("").is_err());
        assert!(Results::parse("t\n").is_err());
        // blank lines skipped, CRLF, lines counted in the file
        let r = Results::parse("t, a\r\n\n0,1\r\n\n1,x\n").err().unwrap();
        assert_eq!(r.0, 5);
        let r = Results::parse("\n t ,a \r\n0, 1\r\n").unwrap();
        assert_eq!(r.names(), ["t", "a"]);
        assert_eq!(r.column("a"), Some(&[1.0][..]));
    }

    /// A CSV of `n` rows: `t`, a sine with a spike at row `spike`, a ramp, a cosine.
    fn csv(n: usize, spike: usize) -> String {
        let mut s = String::from("t,y,ramp,x\n");
        for i in 0..n {
            let t = i as f64 * 1e-3;
            let y = if i == spike { 50.0 } else { (7.0 * t).sin() };
            s.push_str(&format!("{t},{y},{},{}\n", 2.0 * t, (7.0 * t).cos()));
        }
        s
    }

    fn decimated(text: &str, columns: &[&str], max: usize) -> Results {
        match Results::from_lines(text.as_bytes(), Some(columns), Some(max)) {
            Ok(r) => r,
            Err(_) => panic!("refused"),
        }
    }

    /// The plot reader keeps at most its limit of rows, only the columns asked for, and
    /// every extreme: the spike, the ends, each column's minimum and maximum.
    #[test]
    fn the_plot_reader_keeps_at_most_its_limit_and_every_extreme() {
        let n = 200_003;
        let text = csv(n, 123_457);
        let r = decimated(&text, &["y", "x"], 1000);
        assert_eq!(r.rows_read(), n);
        assert!(r.rows_held() <= 1000, "{} rows held", r.rows_held());
        assert!(r.rows_held() >= 250, "{} rows held", r.rows_held());
        assert!(r.bucket() >= n / 1000, "bucket {}", r.bucket());
        assert!(r.column("ramp").is_none(), "a column not drawn is not held");
        assert_eq!(r.names(), ["t", "y", "ramp", "x"]);
        let (t, y, x) = (r.time(), r.column("y").unwrap(), r.column("x").unwrap());
        assert_eq!(
            (t.len(), y.len(), x.len()),
            (r.rows_held(), t.len(), t.len())
        );
        assert_eq!(t[0], 0.0);
        assert_eq!(*t.last().unwrap(), (n - 1) as f64 * 1e-3);
        assert!(t.windows(2).all(|w| w[0] < w[1]), "rows in order");
        let max = y.iter().copied().fold(f64::MIN, f64::max);
        assert_eq!(max, 50.0, "the one-row spike is kept");
        // every bucket keeps its own extremes: compare with the full file bucket by bucket
        let full = Results::parse(&text).unwrap();
        let (ft, fy) = (full.time(), full.column("y").unwrap());
        let b = r.bucket();
        for (k, chunk) in fy.chunks(b).enumerate() {
            let lo = chunk.iter().copied().fold(f64::MAX, f64::min);
            let hi = chunk.iter().copied().fold(f64::MIN, f64::max);
            let span = (ft[k * b], ft[(k * b + chunk.len() - 1).min(n - 1)]);
            let held: Vec<f64> = t
                .iter()
                .zip(y)
                .filter(|(&tt, _)| tt >= span.0 && tt <= span.1)
                .map(|(_, &v)| v)
                .collect();
            assert!(held.contains(&lo) && held.contains(&hi), "bucket {k}");
        }
        // each held row is a row of the file (x against y stays on the data)
        for (i, &tt) in t.iter().enumerate().step_by(17) {
            let j = (tt / 1e-3).round() as usize;
            assert_eq!((y[i], x[i]), (fy[j], full.column("x").unwrap()[j]));
        }
    }

    #[test]
    fn a_file_within_the_limit_is_held_whole_and_decimation_is_deterministic() {
        let text = csv(900, 5);
        let r = decimated(&text, &["y"], 1000);
        assert_eq!((r.rows_held(), r.bucket()), (900, 1));
        let full = Results::parse(&text).unwrap();
        assert_eq!(r.column("y"), full.column("y"));
        // decimated in stages while streaming = one selection with the final bucket
        let text = csv(50_000, 777);
        let r = decimated(&text, &["y"], 1000);
        let mut all = Decimated::new(2, None);
        for (&t, &y) in full_rows(&text).0.iter().zip(&full_rows(&text).1) {
            all.push(&[t, y]);
        }
        all.bucket = r.bucket();
        let once = all.finish();
        assert_eq!(r.time(), once[0].as_slice());
        assert_eq!(r.column("y").unwrap(), once[1].as_slice());
    }

    fn full_rows(text: &str) -> (Vec<f64>, Vec<f64>) {
        let f = Results::parse(text).unwrap();
        (f.time().to_vec(), f.column("y").unwrap().to_vec())
    }

    #[test]
    fn a_bad_cell_in_a_column_not_drawn_is_still_refused() {
        let e = Results::from_lines("t,a,b\n0,1,2\n1,1,zz\n".as_bytes(), Some(&["a"]), Some(10));
        assert!(matches!(e, Err(Failure::Line(3, m)) if m.contains("zz")));
    }
}
