//! Text helpers of the HTML report: escaping, number and date formatting,
//! base64 data URIs, and the citation of a value from a run file.
//!
//! Every value the report takes from a JSON file is written by [`cite`]:
//! `<span data-src="FILE#POINTER">text</span>`, where `POINTER` is the
//! value's JSON pointer in `FILE`. A reader (or a test) can check each
//! number against its source; none is typed by hand.

use serde_json::Value;

/// Escapes `&`, `<`, `>`, `"` and `'` for HTML text and attribute values.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for ch in s.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// A number for reading: whole numbers in full, others to six significant
/// digits with trailing zeros dropped (`1234.57`, `0.0123457`), so a value
/// shown differs from the file's by at most 5e-6 relative.
pub fn fmt_num(v: f64) -> String {
    if !v.is_finite() {
        return v.to_string();
    }
    if v == v.trunc() && v.abs() < 1e15 {
        return format!("{}", v as i64);
    }
    let magnitude = v.abs().log10().floor() as i32;
    let decimals = (5 - magnitude).clamp(0, 15) as usize;
    let s = format!("{v:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" { "0".into() } else { s }
}

/// The text of a JSON value: numbers by [`fmt_num`], strings as they are,
/// booleans as `yes`/`no`, arrays of numbers joined by `, `; escaped.
pub fn value_text(v: &Value) -> String {
    match v {
        Value::Number(n) => n.as_f64().map_or_else(|| n.to_string(), fmt_num),
        Value::String(s) => escape(s),
        Value::Bool(b) => if *b { "yes" } else { "no" }.into(),
        Value::Array(items) => items.iter().map(value_text).collect::<Vec<_>>().join(", "),
        Value::Null => "—".into(),
        Value::Object(_) => escape(&v.to_string()),
    }
}

/// The value at `pointer` in `json` (the contents of `file`), cited:
/// `<span data-src="file#pointer">text</span>`; a missing value shows as
/// "not in file", uncited.
pub fn cite(file: &str, json: &Value, pointer: &str) -> String {
    match json.pointer(pointer) {
        Some(v) => format!(
            "<span data-src=\"{}#{}\">{}</span>",
            escape(file),
            escape(pointer),
            value_text(v)
        ),
        None => "<span class=\"missing\">not in file</span>".into(),
    }
}

/// Standard base64 (RFC 4648, with padding).
pub fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = u32::from(b[0]) << 16 | u32::from(b[1]) << 8 | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// A PNG as a `data:` URI.
pub fn png_uri(png: &[u8]) -> String {
    format!("data:image/png;base64,{}", base64(png))
}

/// Seconds since the Unix epoch as `YYYY-MM-DD hh:mm:ss UTC` (proleptic
/// Gregorian calendar; Howard Hinnant's `civil_from_days`).
pub fn utc_date(unix: u64) -> String {
    let days = (unix / 86_400) as i64;
    let secs = unix % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02} {:02}:{:02}:{:02} UTC",
        secs / 3600,
        secs / 60 % 60,
        secs % 60
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escaping_covers_markup_and_quotes() {
        assert_eq!(
            escape(r#"<a href="x">&'</a>"#),
            "&lt;a href=&quot;x&quot;&gt;&amp;&#39;&lt;/a&gt;"
        );
    }

    #[test]
    fn numbers_keep_six_significant_digits() {
        assert_eq!(fmt_num(1234.5678), "1234.57");
        assert_eq!(fmt_num(0.012345678), "0.0123457");
        assert_eq!(fmt_num(200.0), "200");
        assert_eq!(fmt_num(-0.0), "0");
        assert_eq!(fmt_num(1.24), "1.24");
        assert_eq!(fmt_num(-1e-7), "-0.0000001");
        assert_eq!(fmt_num(1.5e20), "150000000000000000000");
        assert_eq!(fmt_num(f64::INFINITY), "inf");
    }

    #[test]
    fn base64_matches_rfc_4648_vectors() {
        for (plain, coded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(plain.as_bytes()), coded);
        }
    }

    #[test]
    fn dates_are_utc_calendar_dates() {
        assert_eq!(utc_date(0), "1970-01-01 00:00:00 UTC");
        assert_eq!(utc_date(951_825_600), "2000-02-29 12:00:00 UTC");
        assert_eq!(utc_date(1_795_316_463), "2026-11-22 03:01:03 UTC");
    }

    #[test]
    fn citations_carry_their_pointer() {
        let v: Value = serde_json::from_str(r#"{"a": [1.5, 2], "s": "<x>", "t": true}"#).unwrap();
        assert_eq!(
            cite("summary.json", &v, "/a/0"),
            "<span data-src=\"summary.json#/a/0\">1.5</span>"
        );
        assert_eq!(
            cite("f", &v, "/s"),
            "<span data-src=\"f#/s\">&lt;x&gt;</span>"
        );
        assert_eq!(cite("f", &v, "/a"), "<span data-src=\"f#/a\">1.5, 2</span>");
        assert_eq!(cite("f", &v, "/t"), "<span data-src=\"f#/t\">yes</span>");
        assert!(cite("f", &v, "/zz").contains("not in file"));
    }
}
