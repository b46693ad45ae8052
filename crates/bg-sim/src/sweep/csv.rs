//! The summary's CSV fields: quoting one field ([`csv_field`]) and splitting a line back
//! ([`csv_split`]), shared by the run rows and the summary reader.

/// RFC 4180 quoting where needed; line breaks become ` / ` so one run is one line.
pub(super) fn csv_field(s: &str) -> String {
    let s = s.replace("\r\n", " / ").replace(['\n', '\r'], " / ");
    if s.contains([',', '"']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s
    }
}

/// Split one CSV line written by [`csv_field`] into fields.
pub(super) fn csv_split(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            ('"', q) => quoted = !q,
            (',', false) => out.push(std::mem::take(&mut cur)),
            (c, _) => cur.push(c),
        }
    }
    out.push(cur);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_fields_round_trip() {
        let f = ["a", "b,c", "say \"hi\"", "two\nlines"];
        let l: Vec<String> = f.iter().map(|s| csv_field(s)).collect();
        let back = csv_split(&l.join(","));
        assert_eq!(back, ["a", "b,c", "say \"hi\"", "two / lines"]);
    }
}
