//! The dialect of a CSV file, sniffed from its first lines: the separator (`,`, `;` or tab)
//! and, with `;` or tab, decimal commas (what pandas writes with `to_csv(sep=';',
//! decimal=',')`).

/// How a CSV file separates cells and writes decimals.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dialect {
    /// The cell separator: `b','`, `b';'` or `b'\t'`.
    pub delimiter: u8,
    /// Numbers are written with a decimal comma (`1,5`); only with `;` or tab.
    pub decimal_comma: bool,
}

impl Default for Dialect {
    fn default() -> Self {
        Dialect { delimiter: b',', decimal_comma: false }
    }
}

impl Dialect {
    /// The separator as a word, for messages.
    pub fn describe(&self) -> String {
        let sep = match self.delimiter {
            b';' => "`;`",
            b'\t' => "tab",
            _ => "`,`",
        };
        if self.decimal_comma {
            format!("{sep}-separated, decimal commas")
        } else {
            format!("{sep}-separated")
        }
    }

    /// A cell as a number in this dialect (`1,5` is 1.5 with decimal commas), `None` when the
    /// cell is empty or no number.
    pub fn number(&self, cell: &str) -> Option<f64> {
        let t = cell.trim();
        if t.is_empty() {
            return None;
        }
        if self.decimal_comma && t.matches(',').count() == 1 {
            return t.replace(',', ".").parse::<f64>().ok();
        }
        t.parse::<f64>().ok()
    }
}

/// The cells of one line split at `sep` outside double quotes.
fn split_line(line: &str, sep: char) -> Vec<&str> {
    let mut cells = Vec::new();
    let (mut quoted, mut start) = (false, 0);
    for (i, c) in line.char_indices() {
        if c == '"' {
            quoted = !quoted;
        } else if c == sep && !quoted {
            cells.push(&line[start..i]);
            start = i + 1;
        }
    }
    cells.push(&line[start..]);
    cells
}

/// A cell written with a decimal comma: digits, one comma, digits (an exponent allowed).
fn decimal_comma_cell(cell: &str) -> bool {
    let t = cell.trim().trim_start_matches(['+', '-']);
    let Some((int, frac)) = t.split_once(',') else {
        return false;
    };
    let frac = frac.split_once(['e', 'E']).map_or(frac, |(m, _)| m);
    !int.is_empty()
        && !frac.is_empty()
        && int.chars().all(|c| c.is_ascii_digit())
        && frac.chars().all(|c| c.is_ascii_digit())
}

/// Sniffs the dialect from the first (up to 50) non-empty lines: `;` when every line splits
/// into the same number (≥ 2) of cells at `;`, else tab likewise, else `,`. With `;` or tab,
/// decimal commas when some cell is a decimal-comma number.
pub fn sniff(text: &str) -> Dialect {
    let lines: Vec<&str> =
        text.lines().map(|l| l.trim_end_matches('\r')).filter(|l| !l.trim().is_empty()).take(50).collect();
    let consistent = |sep: char| {
        let counts: Vec<usize> = lines.iter().map(|l| split_line(l, sep).len()).collect();
        counts.first().is_some_and(|&c| c >= 2 && counts.iter().all(|&k| k == c))
    };
    let Some(sep) = [';', '\t'].into_iter().find(|&s| consistent(s)) else {
        return Dialect::default();
    };
    let decimal_comma = lines.iter().any(|l| split_line(l, sep).iter().any(|c| decimal_comma_cell(c)));
    Dialect { delimiter: sep as u8, decimal_comma }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn separators_and_decimal_commas() {
        assert_eq!(sniff("a,b\n1,2\n"), Dialect { delimiter: b',', decimal_comma: false });
        assert_eq!(sniff("1.5\n2\n"), Dialect::default());
        assert_eq!(sniff(";load\n2015-01-01;1,5\n2015-01-02;\n"), Dialect { delimiter: b';', decimal_comma: true });
        assert_eq!(sniff("a;b\n1;2\n"), Dialect { delimiter: b';', decimal_comma: false });
        assert_eq!(sniff("\tload\n0\t1.5\n1\t2\n"), Dialect { delimiter: b'\t', decimal_comma: false });
        // a quoted `;` does not make a `;` file
        assert_eq!(sniff("name,v\n\"a;b\",1\n\"c;d\",2\n").delimiter, b',');
        // a comma file whose lines hold no `;` consistently stays a comma file
        assert_eq!(sniff("x,v\n1,2;3\n4,5\n").delimiter, b',');
        let d = sniff("depth;temp\n0,5;1,0\n");
        assert_eq!(
            (d.number("0,5"), d.number("-1,25e-3"), d.number("2"), d.number("")),
            (Some(0.5), Some(-1.25e-3), Some(2.0), None)
        );
        assert_eq!(Dialect::default().number("0,5"), None);
    }
}
