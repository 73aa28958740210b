//! Text helpers of the HTML report: number and date formatting, base64
//! data URIs, the character references the page writes by name, SVG's
//! self-closed elements, and the citation of a value from a run file. The
//! page itself is a [`maud`] template, which escapes every value it splices
//! in.
//!
//! Every value the report takes from a JSON file is written by [`cite`]:
//! `<span data-src="FILE#POINTER">text</span>`, where `POINTER` is the
//! value's JSON pointer in `FILE`. A reader (or a test) can check each
//! number against its source; none is typed by hand.

use maud::{Markup, PreEscaped, Render, html};
use serde_json::Value;

/// `&middot;`: the page's text keeps the character references it always
/// wrote, so that it stays ASCII where it can and byte-identical.
pub(crate) const MIDDOT: PreEscaped<&str> = PreEscaped("&middot;");
/// `&nbsp;`.
pub(crate) const NBSP: PreEscaped<&str> = PreEscaped("&nbsp;");
/// `&sup2;`.
pub(crate) const SUP2: PreEscaped<&str> = PreEscaped("&sup2;");
/// `&times;`.
pub(crate) const TIMES: PreEscaped<&str> = PreEscaped("&times;");
/// `&asymp;`.
pub(crate) const ASYMP: PreEscaped<&str> = PreEscaped("&asymp;");

/// A number for reading: whole numbers in full, others to six significant
/// digits with trailing zeros dropped (`1234.57`, `0.0123457`), so a value
/// shown differs from the file's by at most 5e-6 relative.
pub(crate) fn fmt_num(v: f64) -> String {
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
/// booleans as `yes`/`no`, arrays of numbers joined by `, `; plain text,
/// for the template to escape.
pub(crate) fn value_text(v: &Value) -> String {
    match v {
        Value::Number(n) => n.as_f64().map_or_else(|| n.to_string(), fmt_num),
        Value::String(s) => s.clone(),
        Value::Bool(b) => if *b { "yes" } else { "no" }.into(),
        Value::Array(items) => items.iter().map(value_text).collect::<Vec<_>>().join(", "),
        Value::Null => "—".into(),
        Value::Object(_) => v.to_string(),
    }
}

/// The value at `pointer` in `json` (the contents of `file`), cited:
/// `<span data-src="file#pointer">text</span>`; a missing value shows as
/// "not in file", with the place it was looked for in `data-missing`.
pub(crate) fn cite(file: &str, json: &Value, pointer: &str) -> Markup {
    match json.pointer(pointer) {
        Some(v) => html! { span data-src={ (file) "#" (pointer) } { (value_text(v)) } },
        None => {
            html! { span class="missing" data-missing={ (file) "#" (pointer) } { "not in file" } }
        }
    }
}

/// An empty SVG element closed as SVG writes it, `<name key="value"/>`
/// (a template's `name;` would leave it open, and the HTML parser would
/// nest what follows inside it); the values escaped.
pub(crate) fn svg_empty(name: &str, attributes: &[(&str, &dyn Render)]) -> Markup {
    let mut out = String::from("<");
    out.push_str(name);
    for (key, value) in attributes {
        out.push(' ');
        out.push_str(key);
        out.push_str("=\"");
        value.render_to(&mut out);
        out.push('"');
    }
    out.push_str("/>");
    PreEscaped(out)
}

/// Standard base64 (RFC 4648, with padding).
pub(crate) fn base64(bytes: &[u8]) -> String {
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
pub(crate) fn png_uri(png: &[u8]) -> String {
    format!("data:image/png;base64,{}", base64(png))
}

/// Seconds since the Unix epoch as `YYYY-MM-DD hh:mm:ss UTC` (proleptic
/// Gregorian calendar; Howard Hinnant's `civil_from_days`).
pub(crate) fn utc_date(unix: u64) -> String {
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
    fn svg_elements_close_themselves_and_escape_their_values() {
        assert_eq!(
            svg_empty("rect", &[("x", &1.5), ("fill", &r#"<"&'>"#)]).into_string(),
            "<rect x=\"1.5\" fill=\"&lt;&quot;&amp;'&gt;\"/>"
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
        let cite = |file: &str, pointer: &str| cite(file, &v, pointer).into_string();
        assert_eq!(
            cite("summary.json", "/a/0"),
            "<span data-src=\"summary.json#/a/0\">1.5</span>"
        );
        assert_eq!(cite("f", "/s"), "<span data-src=\"f#/s\">&lt;x&gt;</span>");
        assert_eq!(cite("f", "/a"), "<span data-src=\"f#/a\">1.5, 2</span>");
        assert_eq!(cite("f", "/t"), "<span data-src=\"f#/t\">yes</span>");
        assert_eq!(
            cite("a\"&", "/t"),
            "<span data-src=\"a&quot;&amp;#/t\">yes</span>"
        );
        assert!(cite("f", "/zz").contains("not in file"));
    }
}
