//! A strict check of a `.npy` header before npyz parses it: the header must be the
//! dictionary `numpy.save` writes (`{'descr': '<f8', 'fortran_order': False, 'shape': (3, 4), }`),
//! of bounded length. npyz parses the header with a general Python-literal grammar whose
//! backtracking takes minutes on some crafted headers (found by fuzzing); a header that passes
//! this check is plain enough for it.

use crate::error::{Error, Result};

/// The longest header accepted: numpy writes a few hundred bytes.
const MAX_HEADER: usize = 1 << 16;

/// Checks the header of `.npy` bytes.
///
/// # Errors
/// An input error saying what is wrong with the header.
pub fn check(bytes: &[u8]) -> Result<()> {
    let bad = |why: &str| Error::input(format!("not a readable .npy array: {why}"));
    if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" {
        return Err(bad("no `\\x93NUMPY` magic"));
    }
    let (len, start) = match bytes[6] {
        1 => (usize::from(u16::from_le_bytes([bytes[8], bytes[9]])), 10),
        2 | 3 if bytes.len() >= 12 => (u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize, 12),
        v => return Err(bad(&format!("format version {v} (numpy writes 1, 2 or 3)"))),
    };
    if len > MAX_HEADER {
        return Err(bad(&format!("a header of {len} bytes (numpy writes a few hundred)")));
    }
    let header = bytes.get(start..start + len).ok_or_else(|| bad("the file ends inside the header"))?;
    let text = std::str::from_utf8(header).map_err(|_| bad("the header is not text"))?;
    dictionary(text.trim_end()).map_err(|why| bad(&format!("the header is not the dictionary numpy writes ({why})")))
}

/// `{'key': value, ...}` with string, boolean and integer-tuple values only.
fn dictionary(text: &str) -> std::result::Result<(), String> {
    let mut s = text.strip_prefix('{').ok_or("no `{`")?.trim_start();
    loop {
        if let Some(rest) = s.strip_prefix('}') {
            return if rest.trim().is_empty() { Ok(()) } else { Err("text after `}`".into()) };
        }
        s = string(s)?.trim_start();
        s = s.strip_prefix(':').ok_or("no `:` after a key")?.trim_start();
        s = value(s)?.trim_start();
        if let Some(rest) = s.strip_prefix(',') {
            s = rest.trim_start();
        } else if !s.starts_with('}') {
            return Err("no `,` between entries".into());
        }
    }
}

/// A quoted string of plain characters (dtype codes, key names); the rest of the text.
fn string(s: &str) -> std::result::Result<&str, String> {
    let q = s.chars().next().filter(|&c| c == '\'' || c == '"').ok_or("a key or value that is not a string")?;
    let body = &s[1..];
    let end = body.find(q).ok_or("an unterminated string")?;
    if !body[..end].chars().all(|c| c.is_ascii_alphanumeric() || "<>|=_".contains(c)) {
        return Err(format!("the string `{}` has characters numpy does not write", &body[..end]));
    }
    Ok(&body[end + 1..])
}

fn value(s: &str) -> std::result::Result<&str, String> {
    if s.starts_with('\'') || s.starts_with('"') {
        return string(s);
    }
    for word in ["True", "False"] {
        if let Some(rest) = s.strip_prefix(word) {
            return Ok(rest);
        }
    }
    let mut rest = s.strip_prefix('(').ok_or("a value that is not a string, boolean or tuple")?;
    loop {
        rest = rest.trim_start();
        if let Some(r) = rest.strip_prefix(')') {
            return Ok(r);
        }
        let digits = rest.find(|c: char| !c.is_ascii_digit()).unwrap_or(rest.len());
        if digits == 0 {
            return Err("a shape entry that is not a number".into());
        }
        rest = rest[digits..].trim_start();
        rest = rest.strip_prefix('L').unwrap_or(rest).trim_start();
        if let Some(r) = rest.strip_prefix(',') {
            rest = r;
        } else if !rest.starts_with(')') {
            return Err("no `,` in the shape".into());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn npy(header: &str) -> Vec<u8> {
        let mut out = b"\x93NUMPY\x01\x00".to_vec();
        out.extend_from_slice(&(header.len() as u16).to_le_bytes());
        out.extend_from_slice(header.as_bytes());
        out
    }

    #[test]
    fn numpy_headers_pass_and_others_do_not() {
        for ok in [
            "{'descr': '<f8', 'fortran_order': False, 'shape': (3, 4), }          \n",
            "{'descr': '|b1', 'fortran_order': True, 'shape': (5,), }\n",
            "{'descr': '>i8', 'fortran_order': False, 'shape': (), }\n",
        ] {
            assert!(check(&npy(ok)).is_ok(), "{ok}");
        }
        for bad in [
            "{'descr': '<f8\\x', 'fortran_order': False, 'shape': (3,), }",
            "{'descr': [('a', '<f8')], 'fortran_order': False, 'shape': (3,), }",
            "{'descr': '<f8', 'shape': (3, -1), }",
            "{'descr': '<f8' 'shape': (3,), }",
            "{'descr': '<f8', 'shape': (3,), } x",
            "{'descr': '<f8",
        ] {
            let e = check(&npy(bad)).unwrap_err().to_string();
            assert!(e.contains("not a readable .npy"), "{bad}: {e}");
        }
    }
}
