//! Handles' transforms: the affine [`Transform`] and `pose.json` (SPEC.md, "Formats").

use super::rotation::{det, is_singular, Mat3};
use crate::error::{Error, Result};

/// An affine transform: rows `[[a,b,c,tx],[d,e,f,ty],[g,h,i,tz]]` (`p' = A p + t`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform(pub [[f64; 4]; 3]);

impl Transform {
    /// The identity transform.
    pub fn identity() -> Self {
        Transform([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]])
    }

    /// `A p + t`.
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        self.0.map(|r| r[0] * p[0] + r[1] * p[1] + r[2] * p[2] + r[3])
    }

    /// The linear part `A`.
    pub(super) fn linear(&self) -> Mat3 {
        self.0.map(|r| [r[0], r[1], r[2]])
    }

    /// The translation `t`.
    pub(super) fn translation(&self) -> [f64; 3] {
        self.0.map(|r| r[3])
    }
}

/// Parses `pose.json` text: `{"transforms": {"head": [[a,b,c,tx],[d,e,f,ty],[g,h,i,tz]], ...}}`.
///
/// A 4×4 matrix whose last row is `[0,0,0,1]` is accepted too. Returns the transforms by name
/// in file order. Errors ([`Error::input`], the caller attaches the file): malformed JSON, no
/// (or an empty) `"transforms"` object, a name given twice, a matrix that is not 3×4 or 4×4, a
/// 4×4 one whose last row is not `[0,0,0,1]`, an entry that is not a finite number, a singular
/// linear part. Other top-level keys are ignored.
pub fn parse_pose(text: &str) -> Result<Vec<(String, Transform)>> {
    let file: PoseFile = serde_json::from_str(text).map_err(|e| Error::input(format!("invalid pose JSON: {e}")))?;
    let Some(entries) = file.transforms else {
        return Err(Error::input(
            "pose JSON has no \"transforms\" (expected {\"transforms\": {\"name\": [[a,b,c,tx],[d,e,f,ty],[g,h,i,tz]], ...}})",
        ));
    };
    if entries.is_empty() {
        return Err(Error::input("pose JSON: \"transforms\" is empty"));
    }
    let mut out: Vec<(String, Transform)> = Vec::with_capacity(entries.len());
    for (name, value) in entries {
        if out.iter().any(|(n, _)| *n == name) {
            return Err(Error::input(format!("pose JSON: transform `{name}` is given twice")));
        }
        let t = transform_from_json(&name, &value)?;
        out.push((name, t));
    }
    Ok(out)
}

/// The top level of `pose.json`; keeps the transforms in file order (serde_json's own map
/// sorts its keys).
struct PoseFile {
    transforms: Option<Vec<(String, serde_json::Value)>>,
}

impl<'de> serde::Deserialize<'de> for PoseFile {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct Top;
        impl<'de> serde::de::Visitor<'de> for Top {
            type Value = PoseFile;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an object {\"transforms\": {...}}")
            }
            fn visit_map<M: serde::de::MapAccess<'de>>(self, mut map: M) -> std::result::Result<PoseFile, M::Error> {
                let mut transforms = None;
                while let Some(key) = map.next_key::<String>()? {
                    if key == "transforms" {
                        if transforms.is_some() {
                            return Err(serde::de::Error::duplicate_field("transforms"));
                        }
                        transforms = Some(map.next_value::<Option<Ordered>>()?.map(|o| o.0));
                    } else {
                        map.next_value::<serde::de::IgnoredAny>()?;
                    }
                }
                Ok(PoseFile { transforms: transforms.flatten() })
            }
        }
        d.deserialize_map(Top)
    }
}

/// A JSON object read as its entries in file order.
struct Ordered(Vec<(String, serde_json::Value)>);

impl<'de> serde::Deserialize<'de> for Ordered {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct Entries;
        impl<'de> serde::de::Visitor<'de> for Entries {
            type Value = Ordered;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an object of named transforms {\"name\": [[a,b,c,tx],[d,e,f,ty],[g,h,i,tz]], ...}")
            }
            fn visit_map<M: serde::de::MapAccess<'de>>(self, mut map: M) -> std::result::Result<Ordered, M::Error> {
                let mut out = Vec::new();
                while let Some(entry) = map.next_entry::<String, serde_json::Value>()? {
                    out.push(entry);
                }
                Ok(Ordered(out))
            }
        }
        d.deserialize_map(Entries)
    }
}

/// One transform of `pose.json`, checked.
fn transform_from_json(name: &str, value: &serde_json::Value) -> Result<Transform> {
    let shape = |what: String| {
        Error::input(format!(
            "pose JSON: transform `{name}` must be a 3x4 matrix [[a,b,c,tx],[d,e,f,ty],[g,h,i,tz]] \
             (or 4x4 with last row [0,0,0,1]); {what}"
        ))
    };
    let rows = value.as_array().ok_or_else(|| shape(format!("got {value}")))?;
    if rows.len() != 3 && rows.len() != 4 {
        return Err(shape(format!("got {} rows", rows.len())));
    }
    let mut m = [[0.0; 4]; 4];
    for (i, row) in rows.iter().enumerate() {
        let row = row.as_array().ok_or_else(|| shape(format!("row {} is {row}", i + 1)))?;
        if row.len() != 4 {
            return Err(shape(format!("row {} has {} entries", i + 1, row.len())));
        }
        for (j, x) in row.iter().enumerate() {
            let v = x.as_f64().ok_or_else(|| {
                Error::input(format!(
                    "pose JSON: transform `{name}` row {} column {} is not a number: {x}",
                    i + 1,
                    j + 1
                ))
            })?;
            if !v.is_finite() {
                return Err(Error::input(format!(
                    "pose JSON: transform `{name}` row {} column {} is not finite: {v}",
                    i + 1,
                    j + 1
                )));
            }
            m[i][j] = v;
        }
    }
    if rows.len() == 4 && m[3] != [0.0, 0.0, 0.0, 1.0] {
        return Err(Error::input(format!(
            "pose JSON: transform `{name}` is 4x4 but its last row is {:?}, not [0,0,0,1] (projective \
             transforms are not supported)",
            m[3]
        )));
    }
    let t = Transform([m[0], m[1], m[2]]);
    if is_singular(&t.linear()) {
        return Err(Error::input(format!(
            "pose JSON: transform `{name}` has a singular linear part (determinant {:e})",
            det(&t.linear())
        )));
    }
    Ok(t)
}
