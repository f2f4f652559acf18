//! A small JSON reader (RFC 8259) for Basalt's calibration files, so that the library needs
//! no JSON crate: values, strings with their escapes, and numbers read by Rust's own
//! correctly rounded `f64` parser (a written value reads back to the same bits). Errors give
//! the line and column.

use std::ops::Index;

/// A JSON value. Objects keep their members in file order.
#[derive(Clone, Debug, PartialEq)]
pub enum Json {
    /// `null`.
    Null,
    /// `true` or `false`.
    Bool(bool),
    /// A number.
    Number(f64),
    /// A string.
    String(String),
    /// An array.
    Array(Vec<Json>),
    /// An object.
    Object(Vec<(String, Json)>),
}

static NULL: Json = Json::Null;

impl Json {
    /// The member `key` of an object.
    pub fn get(&self, key: &str) -> Option<&Json> {
        match self {
            Json::Object(members) => members.iter().find(|(k, _)| k == key).map(|(_, v)| v),
            _ => None,
        }
    }

    /// The number, if this is one.
    pub fn as_f64(&self) -> Option<f64> {
        match self {
            Json::Number(x) => Some(*x),
            _ => None,
        }
    }

    /// The string, if this is one.
    pub fn as_str(&self) -> Option<&str> {
        match self {
            Json::String(s) => Some(s),
            _ => None,
        }
    }

    /// The elements, if this is an array.
    pub fn as_array(&self) -> Option<&[Json]> {
        match self {
            Json::Array(items) => Some(items),
            _ => None,
        }
    }
}

/// `value["key"]`: the member, or `null` when there is none (or this is not an object).
impl Index<&str> for Json {
    type Output = Json;

    fn index(&self, key: &str) -> &Json {
        self.get(key).unwrap_or(&NULL)
    }
}

/// Parses a JSON document.
pub fn parse(text: &str) -> Result<Json, String> {
    let mut p = Parser { text, at: 0 };
    let value = p.value(0)?;
    p.space();
    if p.at < text.len() {
        return Err(p.error("unexpected text after the document"));
    }
    Ok(value)
}

/// Nesting deeper than this is refused (no stack overflow on hostile input).
const MAX_DEPTH: usize = 128;

struct Parser<'a> {
    text: &'a str,
    at: usize,
}

impl Parser<'_> {
    fn error(&self, what: &str) -> String {
        let before = &self.text[..self.at];
        let line = before.matches('\n').count() + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        format!("line {line}, column {column}: {what}")
    }

    fn peek(&self) -> Option<u8> {
        self.text.as_bytes().get(self.at).copied()
    }

    fn space(&mut self) {
        while matches!(self.peek(), Some(b' ' | b'\t' | b'\n' | b'\r')) {
            self.at += 1;
        }
    }

    fn expect(&mut self, byte: u8) -> Result<(), String> {
        self.space();
        if self.peek() == Some(byte) {
            self.at += 1;
            Ok(())
        } else {
            Err(self.error(&format!("expected `{}`", byte as char)))
        }
    }

    fn value(&mut self, depth: usize) -> Result<Json, String> {
        if depth > MAX_DEPTH {
            return Err(self.error("nested too deeply"));
        }
        self.space();
        match self.peek() {
            Some(b'{') => self.object(depth),
            Some(b'[') => self.array(depth),
            Some(b'"') => self.string().map(Json::String),
            Some(b'-' | b'0'..=b'9') => self.number(),
            Some(_) => {
                for (word, value) in [
                    ("true", Json::Bool(true)),
                    ("false", Json::Bool(false)),
                    ("null", Json::Null),
                ] {
                    if self.text[self.at..].starts_with(word) {
                        self.at += word.len();
                        return Ok(value);
                    }
                }
                Err(self.error("expected a value"))
            }
            None => Err(self.error("the document ends where a value should be")),
        }
    }

    fn object(&mut self, depth: usize) -> Result<Json, String> {
        self.at += 1;
        let mut members = Vec::new();
        self.space();
        if self.peek() == Some(b'}') {
            self.at += 1;
            return Ok(Json::Object(members));
        }
        loop {
            self.space();
            if self.peek() != Some(b'"') {
                return Err(self.error("expected a member name in quotes"));
            }
            let key = self.string()?;
            self.expect(b':')?;
            members.push((key, self.value(depth + 1)?));
            self.space();
            match self.peek() {
                Some(b',') => self.at += 1,
                Some(b'}') => {
                    self.at += 1;
                    return Ok(Json::Object(members));
                }
                _ => return Err(self.error("expected `,` or `}`")),
            }
        }
    }

    fn array(&mut self, depth: usize) -> Result<Json, String> {
        self.at += 1;
        let mut items = Vec::new();
        self.space();
        if self.peek() == Some(b']') {
            self.at += 1;
            return Ok(Json::Array(items));
        }
        loop {
            items.push(self.value(depth + 1)?);
            self.space();
            match self.peek() {
                Some(b',') => self.at += 1,
                Some(b']') => {
                    self.at += 1;
                    return Ok(Json::Array(items));
                }
                _ => return Err(self.error("expected `,` or `]`")),
            }
        }
    }

    /// A number as RFC 8259's grammar has it, converted by Rust's correctly rounded parser.
    fn number(&mut self) -> Result<Json, String> {
        let start = self.at;
        let digits = |p: &mut Self| {
            let from = p.at;
            while matches!(p.peek(), Some(b'0'..=b'9')) {
                p.at += 1;
            }
            p.at > from
        };
        if self.peek() == Some(b'-') {
            self.at += 1;
        }
        let leading_zero = self.peek() == Some(b'0');
        if !digits(self) {
            return Err(self.error("expected digits"));
        }
        if leading_zero && self.at - start > 1 + usize::from(self.text.as_bytes()[start] == b'-') {
            return Err(self.error("a number cannot start with 0"));
        }
        if self.peek() == Some(b'.') {
            self.at += 1;
            if !digits(self) {
                return Err(self.error("expected digits after `.`"));
            }
        }
        if matches!(self.peek(), Some(b'e' | b'E')) {
            self.at += 1;
            if matches!(self.peek(), Some(b'+' | b'-')) {
                self.at += 1;
            }
            if !digits(self) {
                return Err(self.error("expected the exponent's digits"));
            }
        }
        let x: f64 = self.text[start..self.at].parse().expect("a JSON number");
        if !x.is_finite() {
            self.at = start;
            return Err(self.error("the number is beyond the f64 range"));
        }
        Ok(Json::Number(x))
    }

    fn string(&mut self) -> Result<String, String> {
        self.at += 1;
        let mut out = String::new();
        loop {
            let rest = &self.text[self.at..];
            let Some(c) = rest.chars().next() else {
                return Err(self.error("the string is not closed"));
            };
            self.at += c.len_utf8();
            match c {
                '"' => return Ok(out),
                '\\' => {
                    let escape = self
                        .peek()
                        .ok_or_else(|| self.error("the string is not closed"))?;
                    // A non-ASCII escaped character spans several bytes: refused before
                    // stepping one byte into it (an error's position must fall between
                    // characters).
                    if !escape.is_ascii() {
                        return Err(self.error("unknown escape"));
                    }
                    self.at += 1;
                    out.push(match escape {
                        b'"' => '"',
                        b'\\' => '\\',
                        b'/' => '/',
                        b'b' => '\u{8}',
                        b'f' => '\u{c}',
                        b'n' => '\n',
                        b'r' => '\r',
                        b't' => '\t',
                        b'u' => self.unicode_escape()?,
                        _ => return Err(self.error("unknown escape")),
                    });
                }
                c if (c as u32) < 0x20 => {
                    return Err(self.error("a control character inside a string"));
                }
                c => out.push(c),
            }
        }
    }

    /// The character of a `\uXXXX` escape (after the `u`), joining a surrogate pair.
    fn unicode_escape(&mut self) -> Result<char, String> {
        let hex = |p: &mut Self| -> Result<u32, String> {
            let digits = p.text.get(p.at..p.at + 4).unwrap_or("");
            let value = u32::from_str_radix(digits, 16)
                .ok()
                .filter(|_| digits.len() == 4 && digits.bytes().all(|b| b.is_ascii_hexdigit()))
                .ok_or_else(|| p.error("expected four hex digits after \\u"))?;
            p.at += 4;
            Ok(value)
        };
        let first = hex(self)?;
        let code = if (0xd800..0xdc00).contains(&first) {
            if !self.text[self.at..].starts_with("\\u") {
                return Err(self.error("a lone surrogate"));
            }
            self.at += 2;
            let second = hex(self)?;
            if !(0xdc00..0xe000).contains(&second) {
                return Err(self.error("a lone surrogate"));
            }
            0x10000 + ((first - 0xd800) << 10) + (second - 0xdc00)
        } else {
            first
        };
        char::from_u32(code).ok_or_else(|| self.error("a lone surrogate"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn documents_parse_to_their_values() {
        let doc = parse(
            "{\"a\": [1, -2.5e-3, 0, 1E+2], \"b\": {\"c\": \"x\\\"\\u00e9\\ud83d\\ude00\\n\"},\n\t\"d\": [true, false, null], \"e\": {}, \"f\": []}",
        )
        .unwrap();
        assert_eq!(
            doc["a"],
            Json::Array(vec![
                Json::Number(1.0),
                Json::Number(-2.5e-3),
                Json::Number(0.0),
                Json::Number(100.0)
            ])
        );
        assert_eq!(doc["b"]["c"].as_str(), Some("x\"é😀\n"));
        assert_eq!(
            doc["d"],
            Json::Array(vec![Json::Bool(true), Json::Bool(false), Json::Null])
        );
        assert_eq!(doc["e"], Json::Object(vec![]));
        assert_eq!(doc["f"].as_array(), Some(&[][..]));
        assert_eq!(doc["missing"], Json::Null);
    }

    /// Numbers read back to the bits written (Rust's shortest round-trip form).
    #[test]
    fn numbers_round_trip_exactly() {
        for x in [
            0.1f64,
            190.978,
            1.0 / 3.0,
            5e-324,
            1.7976931348623157e308,
            -2.2250738585072014e-308,
        ] {
            for text in [format!("{x}"), format!("{x:e}")] {
                let back = parse(&text).unwrap().as_f64().unwrap();
                assert_eq!(back.to_bits(), x.to_bits(), "{text}");
            }
        }
    }

    #[test]
    fn bad_documents_are_errors_with_the_place() {
        for (text, wanted) in [
            ("{\"a\": 1,\n \"b\" 2}", "line 2, column 6: expected `:`"),
            ("[1, 2", "line 1, column 6: expected `,` or `]`"),
            ("01", "cannot start with 0"),
            ("1.", "expected digits after `.`"),
            ("1e999", "beyond the f64 range"),
            ("\"abc", "not closed"),
            ("\"\\x\"", "unknown escape"),
            // A multi-byte character after a backslash (found by fuzzing: it panicked).
            ("\"n\\Ú\"", "line 1, column 4: unknown escape"),
            ("\"\\ud800\"", "lone surrogate"),
            ("{} x", "unexpected text"),
            ("nul", "expected a value"),
            ("", "ends where a value should be"),
        ] {
            let message = parse(text).expect_err(text);
            assert!(message.contains(wanted), "{text:?}: {message}");
        }
        let deep = "[".repeat(MAX_DEPTH + 2);
        assert!(parse(&deep).unwrap_err().contains("nested too deeply"));
    }
}
