//! Dates and times in a series' x column, as days since 1970-01-01: ISO dates, date-times with
//! optional fractional seconds, naive (taken as they are written) or aware (a UTC offset
//! `+01:00`, `+0100`, `+01`, `Z` or ` UTC`, as pandas writes time-zone-aware timestamps), an
//! aware one counted at the instant it names.

use chrono::{NaiveDate, NaiveDateTime};

/// A parsed x cell: days since 1970-01-01, and whether the text carried a UTC offset.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stamp {
    /// Days since 1970-01-01 (fractional for times; aware stamps at their UTC instant).
    pub days: f64,
    /// The text carried a UTC offset (`Z`, `+01:00`, ` UTC`, …).
    pub aware: bool,
}

/// Splits a trailing UTC offset off a date-time: the rest and the offset in seconds east of
/// UTC. `None` for an offset that is malformed or out of range (hours ≤ 23, minutes ≤ 59).
fn split_offset(t: &str) -> Option<(&str, Option<i64>)> {
    for utc in [" UTC", "UTC", " GMT", "Z", "z"] {
        if let Some(rest) = t.strip_suffix(utc) {
            return Some((rest.trim_end(), Some(0)));
        }
    }
    // an offset sign can only follow the time of day (after `YYYY-MM-DD`)
    let Some(sign_at) = t.get(10..).and_then(|tail| tail.rfind(['+', '-'])).map(|i| i + 10) else {
        return Some((t, None));
    };
    let (rest, offset) = t.split_at(sign_at);
    let sign = if offset.starts_with('-') { -1 } else { 1 };
    let digits: String = offset[1..].chars().filter(|&c| c != ':').collect();
    let colons = offset[1..].matches(':').count();
    if !digits.chars().all(|c| c.is_ascii_digit()) || colons > 1 || (colons == 1 && offset.len() != 6) {
        return None;
    }
    let (h, m) = match digits.len() {
        2 => (digits.parse::<i64>().ok()?, 0),
        4 => (digits[..2].parse::<i64>().ok()?, digits[2..].parse::<i64>().ok()?),
        _ => return None,
    };
    if h > 23 || m > 59 {
        return None;
    }
    Some((rest.trim_end(), Some(sign * (h * 3600 + m * 60))))
}

/// Parses an x cell: `2010-03-01`, `2010-03-01T12:00[:00[.250]]` or with a space, each
/// optionally followed by a UTC offset.
pub fn parse_stamp(s: &str) -> Option<Stamp> {
    let t = s.trim();
    if t.len() < 10 || !t.as_bytes()[..4].iter().all(u8::is_ascii_digit) || t.as_bytes()[4] != b'-' {
        return None;
    }
    let (naive, offset) = split_offset(t)?;
    let epoch = NaiveDate::from_ymd_opt(1970, 1, 1)?.and_hms_opt(0, 0, 0)?;
    let dt = match NaiveDate::parse_from_str(naive, "%Y-%m-%d") {
        Ok(d) => d.and_hms_opt(0, 0, 0)?,
        Err(_) => ["%Y-%m-%dT%H:%M:%S%.f", "%Y-%m-%d %H:%M:%S%.f", "%Y-%m-%dT%H:%M", "%Y-%m-%d %H:%M"]
            .iter()
            .find_map(|fmt| NaiveDateTime::parse_from_str(naive, fmt).ok())?,
    };
    let since = dt - epoch;
    let seconds = since.num_seconds() - offset.unwrap_or(0);
    let nanos = since.subsec_nanos();
    Some(Stamp { days: (seconds as f64 + f64::from(nanos) * 1e-9) / 86400.0, aware: offset.is_some() })
}

/// Days since 1970-01-01 of an ISO date or date-time (`2010-03-01`, `2010-03-01T12:00:00`,
/// `2015-01-01 00:00:00+01:00`): [`parse_stamp`]'s days.
pub fn parse_date_days(s: &str) -> Option<f64> {
    parse_stamp(s).map(|p| p.days)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn days(s: &str) -> f64 {
        parse_date_days(s).unwrap_or_else(|| panic!("`{s}` did not parse"))
    }

    #[test]
    fn naive_dates_and_times() {
        assert_eq!(days("1970-01-02"), 1.0);
        assert_eq!(days("2010-03-01"), 14669.0);
        assert_eq!(days("1970-01-01T12:00:00"), 0.5);
        assert_eq!(days("1970-01-01 06:00"), 0.25);
        // pandas writes milliseconds when a timestamp has them
        assert_eq!(days("1970-01-01 00:00:43.200"), 0.0005);
        assert!(!parse_stamp("2010-03-01").unwrap().aware);
    }

    #[test]
    fn offsets_give_the_instant() {
        // 2015-01-01 00:00 in Paris is 2014-12-31 23:00 UTC
        let utc = days("2014-12-31 23:00:00");
        for s in [
            "2015-01-01 00:00:00+01:00",
            "2015-01-01T00:00:00+0100",
            "2015-01-01T00:00+01",
            "2014-12-31T23:00:00Z",
            "2014-12-31 23:00:00 UTC",
            "2014-12-31 23:00:00+00:00",
            "2014-12-31 18:00:00-05:00",
            "2015-01-01 04:30:00+05:30",
        ] {
            let p = parse_stamp(s).unwrap_or_else(|| panic!("{s}"));
            assert!(p.aware, "{s}");
            assert!((p.days - utc).abs() < 1e-12, "{s}: {} vs {utc}", p.days);
        }
        // the autumn change in Berlin: 02:00+02:00 comes an hour before 02:00+01:00
        let a = days("2015-10-25 02:00:00+02:00");
        let b = days("2015-10-25 02:00:00+01:00");
        assert!((b - a - 1.0 / 24.0).abs() < 1e-9, "{}", b - a);
    }

    #[test]
    fn malformed_offsets_and_non_dates() {
        for s in [
            "2015-01-01 00:00:00+25:00",
            "2015-01-01 00:00:00+01:0",
            "2015-01-01 00:00:00+1",
            "1.5",
            "abc",
            "",
            "2015-13-01",
        ] {
            assert_eq!(parse_stamp(s), None, "{s}");
        }
    }
}
