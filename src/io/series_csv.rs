//! Series as CSV: the input (header optional; `,`, `;` or tab separated, decimal commas with
//! `;` or tab; value column by name or index; optional x column of numbers, ISO dates or
//! date-times, with or without a UTC offset) and the verifiable output
//! `X,input,output,u,role[,filled]`.

use super::csv_dialect::{sniff, Dialect};
pub use super::series_output::{
    read_series_output, stage_series_output, write_series_output, SeriesColumns, SeriesOutput, Texts, XText,
};
pub use super::timestamps::parse_date_days;
use super::timestamps::parse_stamp;
use crate::error::{Error, Location, Result};
use chrono::NaiveDate;
use std::path::Path;

/// How the x coordinate was obtained.
#[derive(Clone, Debug, PartialEq)]
pub enum XSource {
    /// No x column: x = sample index.
    Index,
    /// A numeric column.
    Numeric(String),
    /// A date column, turned into days since the first date.
    Dates(String, NaiveDate),
}

/// A series read from CSV.
#[derive(Clone, Debug, PartialEq)]
pub struct SeriesCsv {
    /// Name of the value column (or its index as text when the file has no header).
    pub column: String,
    /// The values, in file order (NaN where a value is missing, with
    /// [`SeriesCsvOptions::allow_missing`]).
    pub values: Vec<f64>,
    /// x coordinates (days for dates, index without an x column).
    pub x: Vec<f64>,
    /// The x column's original text per row (the index without an x column; numbers written
    /// with a decimal comma get a point), written back out.
    pub x_text: XText,
    /// The x column's header, written back out (`x` without a header, a name or an x column).
    pub x_name: String,
    /// Where x came from.
    pub x_source: XSource,
}

/// Options for [`read_series`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SeriesCsvOptions {
    /// Value column: a header name, or a 0-based index. Default: the last numeric column.
    pub column: Option<String>,
    /// x column: a header name or index, or `none`. Default: the first column if it holds
    /// dates or is named x, t, time or date.
    pub x_column: Option<String>,
    /// Missing values (empty cells, NaN) are read as NaN, to be filled, instead of refused.
    pub allow_missing: bool,
}

#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Number,
    Date,
    Text,
    Empty,
}

fn kind(s: &str, dialect: &Dialect) -> Kind {
    let t = s.trim();
    if t.is_empty() {
        Kind::Empty
    } else if dialect.number(t).is_some() {
        Kind::Number
    } else if parse_stamp(t).is_some() {
        Kind::Date
    } else {
        Kind::Text
    }
}

/// The kind of column `c` of the data rows: the one kind of its non-empty cells, else text.
fn column_kind(data: Rows<'_>, c: usize, dialect: &Dialect) -> Kind {
    let mut k = Kind::Empty;
    for (_, r) in data.iter() {
        match (k, kind(&r[c], dialect)) {
            (_, Kind::Empty) => {}
            (Kind::Empty, x) => k = x,
            (a, b) if a == b => {}
            _ => return Kind::Text,
        }
    }
    k
}

/// Reads a series from a CSV file.
///
/// # Errors
/// Input errors naming the file and the line: unreadable file, empty file, ragged rows, an
/// unknown column, no numeric column, a missing or non-numeric value, NaN or infinity, x
/// values that do not strictly increase or mix times with and without a UTC offset, fewer
/// than 2 samples.
pub fn read_series(path: &Path, options: &SeriesCsvOptions) -> Result<SeriesCsv> {
    let err = |msg: String| Error::input(msg).in_file(path);
    let (table, dialect) = read_rows(path)?;
    let ncols = table.ncols;
    let all = Rows { table: &table, first: 0 };
    // a header: a cell that is text where the first non-empty cell below is a number or a date
    let below = |c: usize| all.iter().skip(1).map(|(_, r)| kind(&r[c], &dialect)).find(|k| *k != Kind::Empty);
    let has_header = table.len() >= 2
        && (0..ncols).any(|c| {
            kind(table.cell(0, c), &dialect) == Kind::Text && matches!(below(c), Some(Kind::Number | Kind::Date))
        });
    let names: Vec<String> = if has_header {
        (0..ncols).map(|c| table.cell(0, c).to_string()).collect()
    } else {
        (0..ncols).map(|c| c.to_string()).collect()
    };
    let data = Rows { table: &table, first: usize::from(has_header) };
    if data.is_empty() {
        return Err(err("the file has a header but no data rows".into()));
    }
    let kinds: Vec<Kind> = (0..ncols).map(|c| column_kind(data, c, &dialect)).collect();
    let find = |spec: &str| -> Result<usize> {
        if let Some(c) = names.iter().position(|n| n == spec) {
            return Ok(c);
        }
        match spec.parse::<usize>() {
            Ok(c) if c < ncols => Ok(c),
            _ => Err(err(format!("no column `{spec}` (columns: {})", names.join(", ")))),
        }
    };
    let explicit_x = match options.x_column.as_deref() {
        Some("none") | None => None,
        Some(spec) => Some(find(spec)?),
    };
    let value_col = match &options.column {
        Some(spec) => find(spec)?,
        None => (0..ncols).rev().find(|&c| kinds[c] == Kind::Number && Some(c) != explicit_x).ok_or_else(|| {
            err(format!(
                "no numeric column (columns: {}; read as {}); choose the value column by name or index",
                names.join(", "),
                dialect.describe()
            ))
        })?,
    };
    let x_col = match options.x_column.as_deref() {
        Some("none") => None,
        Some(spec) => Some(find(spec)?),
        None => {
            let named = ["x", "t", "time", "date"].contains(&names[0].to_ascii_lowercase().as_str()) && has_header;
            (value_col != 0 && (kinds[0] == Kind::Date || (named && kinds[0] == Kind::Number))).then_some(0)
        }
    };
    if x_col == Some(value_col) {
        return Err(err(format!("the x column and the value column are both `{}`", names[value_col])));
    }
    let read = Cells { path, data, dialect };
    let values = read.values(value_col, &names[value_col], options.allow_missing)?;
    let (x, x_text, x_source) = match x_col {
        None => ((0..values.len()).map(|i| i as f64).collect(), XText::Index(values.len()), XSource::Index),
        Some(c) => read.x(&names[c], c, kinds[c] == Kind::Date)?,
    };
    if values.len() < 2 {
        return Err(err(format!("a series needs at least 2 samples, found {}", values.len())));
    }
    let x_name = match x_col {
        Some(c) if has_header && !names[c].trim().is_empty() => names[c].clone(),
        _ => "x".to_string(),
    };
    Ok(SeriesCsv { column: names[value_col].clone(), values, x, x_text, x_name, x_source })
}

/// The non-empty rows of a CSV file, every row with the same number of cells: the cells'
/// text one after another, where each ends, and each row's line (at 10⁷ rows a string per cell
/// and a vector per row held 1.5 GB).
struct Table {
    text: String,
    ends: Vec<usize>,
    lines: Vec<u64>,
    ncols: usize,
}

impl Table {
    fn len(&self) -> usize {
        self.lines.len()
    }

    fn cell(&self, row: usize, c: usize) -> &str {
        let k = row * self.ncols + c;
        let start = if k == 0 { 0 } else { self.ends[k - 1] };
        &self.text[start..self.ends[k]]
    }
}

/// The rows of a [`Table`] from `first` on.
#[derive(Clone, Copy)]
struct Rows<'a> {
    table: &'a Table,
    first: usize,
}

/// One row of a [`Table`]: its cells by column.
#[derive(Clone, Copy)]
struct Row<'a> {
    table: &'a Table,
    row: usize,
}

impl std::ops::Index<usize> for Row<'_> {
    type Output = str;

    fn index(&self, c: usize) -> &str {
        self.table.cell(self.row, c)
    }
}

impl<'a> Rows<'a> {
    fn len(&self) -> usize {
        self.table.len() - self.first
    }

    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The line of row `i` (counted from `first`).
    fn line(&self, i: usize) -> u64 {
        self.table.lines[self.first + i]
    }

    /// Each row with its line.
    fn iter(&self) -> impl Iterator<Item = (u64, Row<'a>)> + 'a {
        let table = self.table;
        (self.first..table.len()).map(move |row| (table.lines[row], Row { table, row }))
    }
}

/// The non-empty rows of a CSV file (UTF-8, a byte-order mark dropped), with their lines,
/// and the file's dialect.
/// A cell's bytes as trimmed text.
fn cell(bytes: &[u8]) -> std::result::Result<&str, std::str::Utf8Error> {
    std::str::from_utf8(bytes).map(str::trim)
}

fn read_rows(path: &Path) -> Result<(Table, Dialect)> {
    let err = |msg: String| Error::input(msg).in_file(path);
    let bytes = std::fs::read(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    super::content::expect_text(path, &bytes, "CSV text")?;
    let text =
        String::from_utf8(bytes).map_err(|e| err(format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to())))?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let dialect = sniff(text);
    let mut reader =
        csv::ReaderBuilder::new().has_headers(false).delimiter(dialect.delimiter).from_reader(text.as_bytes());
    let mut table = Table { text: String::new(), ends: Vec::new(), lines: Vec::new(), ncols: 0 };
    // byte records over text already checked as UTF-8 (a cell between delimiters stays UTF-8),
    // each cell trimmed as a string record's would be (string records validated every cell of
    // 10⁷ rows again)
    let mut rec = csv::ByteRecord::new();
    while reader.read_byte_record(&mut rec).map_err(|e| err(format!("malformed CSV ({}): {e}", dialect.describe())))? {
        let line = rec.position().map(|p| p.line()).unwrap_or(0);
        // each cell trimmed once, into the table; a row of empty cells taken back out
        let (text_len, cells) = (table.text.len(), table.ends.len());
        for c in &rec {
            let c = cell(c).map_err(|_| err(format!("line {line}: not UTF-8 text")))?;
            table.text.push_str(c);
            table.ends.push(table.text.len());
        }
        if table.text.len() == text_len {
            table.ends.truncate(cells);
            continue;
        }
        if table.lines.is_empty() {
            table.ncols = rec.len();
        } else if rec.len() != table.ncols {
            // the reader refuses ragged rows itself; a row of empty cells taken out above is the
            // only way to get here
            return Err(err(format!(
                "malformed CSV ({}): line {line} has {} fields, the first row {}",
                dialect.describe(),
                rec.len(),
                table.ncols
            )));
        }
        table.lines.push(line);
    }
    if table.lines.is_empty() {
        return Err(err("the file is empty".into()));
    }
    Ok((table, dialect))
}

/// The data rows of a file, read column by column.
struct Cells<'a> {
    path: &'a Path,
    data: Rows<'a>,
    dialect: Dialect,
}

impl Cells<'_> {
    fn error(&self, line: u64, msg: String) -> Error {
        Error::input(format!("line {line}: {msg}")).at(Location::Line(line as usize)).in_file(self.path)
    }

    /// The values of column `col` (named `name`): finite numbers, or NaN where one is
    /// missing (an empty cell or NaN) when `allow_missing`.
    fn values(&self, col: usize, name: &str, allow_missing: bool) -> Result<Vec<f64>> {
        let hint = "; --fill-missing fills missing values linearly in x";
        let mut values = Vec::with_capacity(self.data.len());
        for (line, r) in self.data.iter() {
            let cell = &r[col];
            let v = match self.dialect.number(cell) {
                Some(v) => v,
                None if cell.trim().is_empty() && allow_missing => f64::NAN,
                None if cell.trim().is_empty() => {
                    return Err(self.error(line, format!("missing value in column `{name}`{hint}")))
                }
                None => return Err(self.error(line, format!("`{cell}` in column `{name}` is not a number"))),
            };
            if v.is_infinite() || (v.is_nan() && !allow_missing) {
                let why = if v.is_nan() { hint } else { "" };
                return Err(self.error(line, format!("value {v} in column `{name}` is not finite{why}")));
            }
            values.push(v);
        }
        Ok(values)
    }

    /// The x axis from column `c` (named `name`): dates (days since 1970, aware ones at their
    /// instant) or numbers, strictly increasing, with their text.
    fn x(&self, name: &str, c: usize, dates: bool) -> Result<(Vec<f64>, XText, XSource)> {
        let mut x = Vec::with_capacity(self.data.len());
        // the texts are kept from the first that is not its sample's index (`0, 1, 2, …`, as
        // pandas writes a frame's index): an index column is written back as the index (at 10⁷
        // samples its texts were 0.28 GB held through the solve)
        let mut text = Texts::default();
        let mut index = !dates;
        let mut first_aware: Option<(bool, u64, String)> = None;
        for (i, (line, r)) in self.data.iter().enumerate() {
            let cell = r[c].trim();
            if index && !is_index(cell, i) {
                index = false;
                text = Texts::with_capacity(self.data.len());
                (0..i).for_each(|k| text.push(&k.to_string()));
            }
            let v = if dates {
                parse_stamp(cell).map(|s| {
                    match &first_aware {
                        None => first_aware = Some((s.aware, line, cell.to_string())),
                        Some((aware, at, first)) if *aware != s.aware => {
                            let (with, without) =
                                if s.aware { ("has a", "has none") } else { ("has no", "has one") };
                            return Err(self.error(
                                line,
                                format!(
                                    "`{cell}` in x column `{name}` {with} UTC offset but `{first}` (line {at}) {without}: \
                                     a column cannot mix times with and without a time zone"
                                ),
                            ));
                        }
                        _ => {}
                    }
                    Ok(s.days)
                })
            } else {
                self.dialect.number(cell).map(Ok)
            };
            let v = v.transpose()?.filter(|v| v.is_finite()).ok_or_else(|| {
                let what = if dates { "date" } else { "finite number" };
                self.error(line, format!("`{cell}` in x column `{name}` is not a {what}"))
            })?;
            x.push(v);
            if index {
                continue;
            }
            if dates || !self.dialect.decimal_comma {
                text.push(cell);
            } else {
                text.push(&cell.replace(',', "."));
            }
        }
        if let Some(i) = (1..x.len()).find(|&i| x[i] <= x[i - 1]) {
            return Err(self.error(
                self.data.line(i),
                format!(
                    "x column `{name}` must strictly increase, but `{}` follows `{}`",
                    text.get(i),
                    text.get(i - 1)
                ),
            ));
        }
        if index {
            return Ok((x, XText::Index(self.data.len()), XSource::Numeric(name.to_string())));
        }
        let source = if dates {
            let first =
                NaiveDate::from_ymd_opt(1970, 1, 1).expect("valid") + chrono::Duration::days(x[0].floor() as i64);
            XSource::Dates(name.to_string(), first)
        } else {
            XSource::Numeric(name.to_string())
        };
        Ok((x, XText::Text(text), source))
    }
}

/// Whether `cell` is the decimal text of `i` (no sign, no leading zero, no point).
fn is_index(cell: &str, i: usize) -> bool {
    cell.as_bytes() == super::decimal(i, &mut [0u8; 20])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str, content: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("toposmooth-csv-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join(name);
        std::fs::write(&p, content).unwrap();
        p
    }

    #[test]
    fn dates_headers_and_default_column() {
        let p = tmp("a.csv", "date,a,b,label\n2010-03-01,1,10,x\n2010-03-02,2,20,y\n2010-03-05,3,30,z\n");
        let s = read_series(&p, &SeriesCsvOptions::default()).unwrap();
        assert_eq!(s.column, "b");
        assert_eq!(s.values, vec![10.0, 20.0, 30.0]);
        assert_eq!(s.x[1] - s.x[0], 1.0);
        assert_eq!(s.x[2] - s.x[1], 3.0);
        assert!(matches!(s.x_source, XSource::Dates(_, d) if d == NaiveDate::from_ymd_opt(2010, 3, 1).unwrap()));
        let s = read_series(&p, &SeriesCsvOptions { column: Some("a".into()), ..Default::default() }).unwrap();
        assert_eq!(s.values, vec![1.0, 2.0, 3.0]);
        let s = read_series(
            &p,
            &SeriesCsvOptions { column: Some("1".into()), x_column: Some("none".into()), ..Default::default() },
        )
        .unwrap();
        assert_eq!((s.values.clone(), s.x_source), (vec![1.0, 2.0, 3.0], XSource::Index));
    }

    /// An x column of the samples' indices (`0, 1, 2, …`) is kept as the index, with its
    /// name; any other text keeps every text, the ones before it included.
    #[test]
    fn an_index_column_is_the_index_and_other_texts_are_kept() {
        let p = tmp("index.csv", "x,v\n0,5\n1,3\n2,4\n3,1\n");
        let s = read_series(&p, &SeriesCsvOptions::default()).unwrap();
        assert_eq!(
            (s.x_text, s.x_source, s.x),
            (XText::Index(4), XSource::Numeric("x".into()), vec![0.0, 1.0, 2.0, 3.0])
        );
        for (name, column) in [
            ("late.csv", ["0", "1", "2", "5"]),
            ("zero.csv", ["0", "1", "02", "3"]),
            ("point.csv", ["0", "1", "2", "3.0"]),
        ] {
            let text = format!("x,v\n{}", column.iter().map(|x| format!("{x},1\n")).collect::<String>());
            let s = read_series(&tmp(name, &text), &SeriesCsvOptions::default()).unwrap();
            assert_eq!(s.x_text.to_vec(), column, "{name}");
            assert!(s.x_text.as_text().is_some(), "{name}");
        }
        let s = read_series(&tmp("first.csv", "x,v\n1,5\n2,3\n"), &SeriesCsvOptions::default()).unwrap();
        assert_eq!(s.x_text.to_vec(), ["1", "2"]);
    }

    #[test]
    fn headerless_single_column() {
        let p = tmp("b.csv", "1.5\n-2\n3e-3\n");
        let s = read_series(&p, &SeriesCsvOptions::default()).unwrap();
        assert_eq!(s.values, vec![1.5, -2.0, 3e-3]);
        assert_eq!(s.x, vec![0.0, 1.0, 2.0]);
    }

    #[test]
    fn errors_name_file_and_line() {
        let cases = [
            ("empty.csv", "", "empty"),
            ("nan.csv", "v\n1\nNaN\n3\n", "line 3"),
            ("missing.csv", "v,w\n1,2\n3,\n4,5\n", "line 3"),
            ("ragged.csv", "a,b\n1,2\n3\n", "malformed"),
            ("dup.csv", "date,v\n2010-01-01,1\n2010-01-01,2\n", "strictly increase"),
            ("one.csv", "v\n1\n", "at least 2"),
            ("text.csv", "a,b\nx,y\nz,w\n", "no numeric column"),
        ];
        for (name, content, needle) in cases {
            let p = tmp(name, content);
            let e = read_series(&p, &SeriesCsvOptions::default()).unwrap_err();
            let msg = e.to_string();
            assert!(msg.contains(name) && msg.contains(needle), "{name}: {msg}");
            assert_eq!(e.exit_code(), 3);
            if needle == "line 3" {
                assert_eq!(e.location(), Some(crate::error::Location::Line(3)), "{name}");
            }
        }
        let p = tmp("c.csv", "a\n1\n2\n");
        let e = read_series(&p, &SeriesCsvOptions { column: Some("zz".into()), ..Default::default() }).unwrap_err();
        assert!(e.to_string().contains("no column `zz`"));
    }

    #[test]
    fn separators_decimal_commas_and_x_names() {
        let opts = SeriesCsvOptions::default();
        let p = tmp("semi.csv", "depth;temp\n0,5;1,0\n1,5;2,25\n3;-1,5\n");
        let s = read_series(&p, &opts).unwrap();
        assert_eq!(
            (s.column.as_str(), s.x_name.as_str()),
            ("temp", "x"),
            "depth is not a name the x column takes by default"
        );
        assert_eq!(s.values, vec![1.0, 2.25, -1.5]);
        let s = read_series(&p, &SeriesCsvOptions { x_column: Some("depth".into()), ..Default::default() }).unwrap();
        assert_eq!(
            (s.x.clone(), s.x_text.clone(), s.x_name.as_str()),
            (vec![0.5, 1.5, 3.0], XText::Text(["0.5", "1.5", "3"].into_iter().collect()), "depth")
        );
        let p = tmp("tab.tsv", "time\tv\n1\t3\n2\t1\n4\t2\n");
        let s = read_series(&p, &opts).unwrap();
        assert_eq!(
            (s.x.clone(), s.values.clone(), s.x_name.as_str()),
            (vec![1.0, 2.0, 4.0], vec![3.0, 1.0, 2.0], "time")
        );
        // pandas' unnamed index column: dates make it x, its empty name becomes `x`
        let p = tmp("unnamed.csv", ",load\n2015-01-01,1\n2015-01-02,2\n");
        let s = read_series(&p, &opts).unwrap();
        assert_eq!((s.x_name.as_str(), s.x[1] - s.x[0]), ("x", 1.0));
    }

    #[test]
    fn aware_timestamps_at_their_instant() {
        let opts = SeriesCsvOptions::default();
        // the night the clocks go back in Berlin: naive, the fourth row would repeat the third
        let p = tmp("dst.csv", ",load\n2015-10-25 01:00:00+02:00,1\n2015-10-25 02:00:00+02:00,2\n2015-10-25 02:00:00+01:00,3\n2015-10-25 03:00:00+01:00,4\n");
        let s = read_series(&p, &opts).unwrap();
        assert!(matches!(s.x_source, XSource::Dates(..)), "{:?}", s.x_source);
        for w in s.x.windows(2) {
            assert!((w[1] - w[0] - 1.0 / 24.0).abs() < 1e-9, "{:?}", s.x);
        }
        assert_eq!(s.x_text.get(2), "2015-10-25 02:00:00+01:00");
        let p = tmp("z.csv", "t,v\n2015-01-01T00:00:00Z,1\n2015-01-01T12:00:00Z,2\n2015-01-02T00:00:00Z,1\n");
        let s = read_series(&p, &opts).unwrap();
        assert_eq!(s.x[1] - s.x[0], 0.5);
        let p =
            tmp("mixed.csv", "t,v\n2015-01-01 00:00:00+01:00,1\n2015-01-01 01:00:00+01:00,2\n2015-01-01 03:00:00,1\n");
        let e = read_series(&p, &opts).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains("mixed.csv") && msg.contains("line 4") && msg.contains("line 2") && msg.contains("time zone"),
            "{msg}"
        );
        assert_eq!(e.location(), Some(crate::error::Location::Line(4)));
    }

    #[test]
    fn missing_values_kept_as_nan_when_allowed() {
        let p = tmp("gaps.csv", "t,v\n0,1\n1,\n2,NaN\n3,4\n");
        let e = read_series(&p, &SeriesCsvOptions::default()).unwrap_err().to_string();
        assert!(e.contains("line 3") && e.contains("--fill-missing"), "{e}");
        let s = read_series(&p, &SeriesCsvOptions { allow_missing: true, ..Default::default() }).unwrap();
        assert_eq!(s.values[0], 1.0);
        assert!(s.values[1].is_nan() && s.values[2].is_nan());
        let p = tmp("inf.csv", "t,v\n0,1\n1,inf\n2,3\n");
        let e =
            read_series(&p, &SeriesCsvOptions { allow_missing: true, ..Default::default() }).unwrap_err().to_string();
        assert!(e.contains("line 3") && e.contains("not finite"), "{e}");
    }
}
