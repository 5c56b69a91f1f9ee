//! Tables of numbers as other tools write them, read one way for every file spectra takes
//! them from (observer files, a scene's `{"csv": …}` spectra): a spectrophotometer's or a
//! spreadsheet's export was refused or misread by one reader and read by the other.
//!
//! - the text is UTF-8 (a BOM allowed), UTF-16 with its BOM or Latin-1 ([`decode`]);
//! - lines end in LF, CRLF or CR alone; blank lines and `#` comment lines are skipped;
//! - the first line is a header if its first field is not a number;
//! - each line's separator is a semicolon if it has one (then a comma is a decimal comma),
//!   else a tab (likewise), else a comma, else runs of spaces; quotes are taken off and a
//!   separator inside them is text (`"0,5"`);
//! - an empty cell is an error naming its line and column, never a reason to shift the columns
//!   after it; empty cells past the expected count (trailing separators) are dropped.
//!
//! What the numbers mean (increasing wavelengths, signs, ranges) is the caller's to check.

use std::borrow::Cow;

/// A file's text: UTF-8; UTF-16 with its byte-order mark (a spreadsheet's "Unicode text"); else
/// Latin-1, byte for byte (a spreadsheet's CSV on Windows is Windows-1252: a header such as
/// `x̄ 2°` or `Wellenlänge` refused the whole file as "not valid UTF-8"). The numbers are ASCII
/// in all of them, so only the header's text can differ.
pub fn decode(bytes: &[u8]) -> String {
    let utf16 = |le: bool| {
        let units = bytes[2..]
            .chunks_exact(2)
            .map(|c| if le { u16::from_le_bytes([c[0], c[1]]) } else { u16::from_be_bytes([c[0], c[1]]) });
        char::decode_utf16(units).map(|c| c.unwrap_or(char::REPLACEMENT_CHARACTER)).collect()
    };
    match bytes {
        [0xff, 0xfe, ..] => utf16(true),
        [0xfe, 0xff, ..] => utf16(false),
        _ => match std::str::from_utf8(bytes) {
            Ok(s) => s.to_string(),
            Err(_) => bytes.iter().map(|&b| b as char).collect(),
        },
    }
}

/// One data line of a table.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// 1-based line number in the file.
    pub line: usize,
    /// Its numbers, exactly as many as the table's columns.
    pub values: Vec<f64>,
}

/// A line that is not a row of the table. Columns are 1-based. Each caller words the message,
/// since only it knows what the columns mean and whether the file's text may be echoed.
#[derive(Clone, Debug, PartialEq)]
pub enum TableError {
    /// The line has `found` cells, not the table's count.
    Columns { line: usize, found: usize },
    /// The cell is empty (`400,,0.3`).
    Empty { line: usize, column: usize },
    /// The cell is not a finite number; `field` is its text, unescaped.
    NotANumber { line: usize, column: usize, field: String },
}

impl TableError {
    pub fn line(&self) -> usize {
        match *self {
            TableError::Columns { line, .. }
            | TableError::Empty { line, .. }
            | TableError::NotANumber { line, .. } => line,
        }
    }
}

/// The data rows of `text`, each of `columns` finite numbers, in file order. The first error
/// ends the iteration, so a caller checking its rows as they come (wavelengths increasing)
/// reports the first bad line of either kind.
pub fn rows(text: &str, columns: usize) -> Rows<'_> {
    // A classic Mac OS export ends its lines in CR alone and was read as one line.
    let text: Cow<str> = if text.contains('\n') { text.into() } else { text.replace('\r', "\n").into() };
    Rows { text, at: 0, line: 0, first: true, columns }
}

/// The iterator of [`rows`].
pub struct Rows<'a> {
    text: Cow<'a, str>,
    at: usize,
    line: usize,
    first: bool,
    columns: usize,
}

impl Iterator for Rows<'_> {
    type Item = Result<Row, TableError>;

    fn next(&mut self) -> Option<Self::Item> {
        while self.at < self.text.len() {
            let rest = &self.text[self.at..];
            let end = rest.find('\n').map_or(rest.len(), |i| i + 1);
            self.at += end;
            self.line += 1;
            let line = rest[..end].trim().trim_start_matches('\u{feff}');
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let fields = split_fields(line, self.columns);
            // A header: the first line, if its first field is not a number. (Every such line was
            // taken for one, so that a file of text ended as "0 data rows" naming no line.)
            if std::mem::take(&mut self.first) && fields.first().is_some_and(|f| f.parse::<f64>().is_err()) {
                continue;
            }
            let row = self.row(&fields);
            if row.is_err() {
                self.at = self.text.len();
            }
            return Some(row);
        }
        None
    }
}

impl Rows<'_> {
    fn row(&self, fields: &[String]) -> Result<Row, TableError> {
        let line = self.line;
        if fields.len() != self.columns {
            return Err(TableError::Columns { line, found: fields.len() });
        }
        let values = fields
            .iter()
            .enumerate()
            .map(|(c, f)| match f.parse::<f64>() {
                Ok(x) if x.is_finite() => Ok(x),
                _ if f.is_empty() => Err(TableError::Empty { line, column: c + 1 }),
                _ => Err(TableError::NotANumber { line, column: c + 1, field: f.clone() }),
            })
            .collect::<Result<_, _>>()?;
        Ok(Row { line, values })
    }
}

/// The fields of one line. The separator is the line's: a semicolon if it has one (then a
/// comma is a decimal comma, as European spreadsheets write `400;0,0143;…`), else a tab (also
/// with decimal commas), else a comma, else runs of spaces. Quotes are taken off and a
/// separator inside them is text (`"0,5"`). An empty field is kept as one — `400,,0.3,0.1`
/// has an empty second column; when separators were runs it was read as three columns and
/// `400,0.1,,0.2,0.3` as four, shifted — but empty fields past `columns` are dropped (a
/// spreadsheet's trailing separators).
fn split_fields(line: &str, columns: usize) -> Vec<String> {
    let sep = [';', '\t', ','].into_iter().find(|&c| line.contains(c));
    let mut fields: Vec<String> = match sep {
        None => line.split_whitespace().map(|f| f.trim_matches('"').trim().to_string()).collect(),
        Some(sep) => {
            let (mut out, mut cur, mut quoted) = (Vec::new(), String::new(), false);
            for c in line.chars() {
                match c {
                    '"' => quoted = !quoted,
                    c if c == sep && !quoted => out.push(std::mem::take(&mut cur)),
                    c => cur.push(c),
                }
            }
            out.push(cur);
            out.into_iter().map(|f| f.trim().to_string()).collect()
        }
    };
    while fields.len() > columns && fields.last().is_some_and(|f| f.is_empty()) {
        fields.pop();
    }
    // A decimal comma: one comma, no point (a comma-separated line cannot have one in a field
    // unless it was quoted, which is how spreadsheets write a decimal comma there).
    for f in &mut fields {
        if f.matches(',').count() == 1 && !f.contains('.') {
            *f = f.replace(',', ".");
        }
    }
    fields
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all(text: &str, columns: usize) -> Result<Vec<(usize, Vec<f64>)>, TableError> {
        rows(text, columns).map(|r| r.map(|r| (r.line, r.values))).collect()
    }

    #[test]
    fn every_separator_and_line_end_gives_the_same_rows() {
        let want = vec![(2, vec![400.0, 0.5]), (4, vec![500.0, 0.25])];
        for text in [
            "nm,R\n400,0.5\n# c\n500,0.25\n",
            "nm;%R\r\n400;0,5\r\n# c\r\n500;0,25\r\n",
            "nm\tR\r400\t0,5\r# c\r500\t0,25\r",
            "\u{feff}\"nm\",\"R\"\n\"400\",\"0,5\"\n# c\n\"500\",\"0,25\"\n",
            "  nm    R\n  400   0.5\n# c\n  500   0.25\n",
            "nm;R;;\n400;0,5;;\n# c\n500;0,25;\n",
        ] {
            assert_eq!(all(text, 2).unwrap(), want, "{text:?}");
        }
    }

    #[test]
    fn utf16_and_latin1_decode() {
        let utf16: Vec<u8> = [0xff, 0xfe]
            .into_iter()
            .chain("λ\tR\n400\t0,5\n".encode_utf16().flat_map(u16::to_le_bytes))
            .collect();
        assert_eq!(decode(&utf16), "λ\tR\n400\t0,5\n");
        let be: Vec<u8> =
            [0xfe, 0xff].into_iter().chain("nm\n".encode_utf16().flat_map(u16::to_be_bytes)).collect();
        assert_eq!(decode(&be), "nm\n");
        assert_eq!(decode(b"Wellenl\xe4nge\n"), "Wellenlänge\n");
    }

    /// The first bad line ends the rows, whichever kind it is, and names its line and column.
    #[test]
    fn bad_lines_are_named() {
        assert_eq!(all("400,1,2\n500,,3\n", 3), Err(TableError::Empty { line: 2, column: 2 }));
        assert_eq!(all("400,1,2\n\n500,1\n", 3), Err(TableError::Columns { line: 3, found: 2 }));
        assert_eq!(
            all("400,1\n500,inf\n600,x\n", 2),
            Err(TableError::NotANumber { line: 2, column: 2, field: "inf".into() })
        );
        let mut r = rows("400,1\n500,x\n600,1\n", 2);
        assert!(r.next().unwrap().is_ok());
        assert_eq!(r.next().unwrap().unwrap_err().line(), 2);
        assert!(r.next().is_none());
        // Only the first line may be a header.
        assert_eq!(
            all("a,b\nc,d\n", 2).unwrap_err(),
            TableError::NotANumber { line: 2, column: 1, field: "c".into() }
        );
    }
}
