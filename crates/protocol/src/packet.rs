//! The text command packet: `<CODE#KEY=VALUE,KEY=VALUE,...>`.
//!
//! This is the protocol of the paper the text channel reproduces, e.g.
//! `<FK#J1=0.785398163397448,J2=0,J3=-1.5707963267949,J4=0,J5=0,J6=0>` or
//! `<IK#TX=0.25,TY=1,TZ=0.6,RX=0,RY=0,RZ=0>`. Every value is a number. The parser is
//! lenient where people typing by hand differ harmlessly (whitespace, key case) and strict
//! where a guess could move a robot wrongly (a comma used as decimal separator, `inf`,
//! duplicate keys). Every error is a distinct variant whose message can be sent back
//! verbatim with [`encode_error`].

use thiserror::Error;

/// Longest packet line accepted, in bytes (the same as the line framer's default).
pub const MAX_PACKET_LEN: usize = crate::line::DEFAULT_MAX_LINE_LEN;
/// Most fields a packet may carry.
pub const MAX_FIELDS: usize = 64;
/// Longest command code, in characters.
pub const MAX_CODE_LEN: usize = 16;
/// Longest key, in characters.
pub const MAX_KEY_LEN: usize = 32;
/// Longest message [`encode_error`] puts in a reply, in characters.
pub const MAX_ERROR_MSG_LEN: usize = 200;

/// How much of an offending piece of input an error message quotes.
const SNIPPET_LEN: usize = 40;

/// One `KEY=VALUE` pair of a packet.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    /// The key, uppercased; ASCII letters, digits and `_`, 1 to [`MAX_KEY_LEN`] long.
    pub key: String,
    /// The value; always finite.
    pub value: f64,
}

/// A parsed command packet.
#[derive(Debug, Clone, PartialEq)]
pub struct Packet {
    /// The command code, uppercased; ASCII letters, digits and `_`, 1 to
    /// [`MAX_CODE_LEN`] long.
    pub code: String,
    /// The fields in the order received; keys are unique.
    pub fields: Vec<Field>,
    /// The line as received, trimmed of surrounding whitespace (for logs and echoes).
    pub raw: String,
}

/// Why a line is not a valid packet. Messages are meant for the peer, in `<ERR#...>`.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum PacketError {
    /// The line is longer than [`MAX_PACKET_LEN`].
    #[error("packet too long: {len} bytes, at most {max} allowed")]
    TooLong {
        /// Length of the line in bytes.
        len: usize,
        /// The limit.
        max: usize,
    },
    /// The line is empty or only whitespace.
    #[error("empty line; expected a packet like <CODE#KEY=VALUE,...>")]
    Empty,
    /// The packet does not start with `<`.
    #[error("packet must start with '<', e.g. <FK#J1=0,J2=0>")]
    MissingOpen,
    /// There is no `>` closing the packet.
    #[error("packet must end with '>', e.g. <FK#J1=0,J2=0>")]
    MissingClose,
    /// Something other than whitespace follows the closing `>`.
    #[error("unexpected text after the closing '>': {text:?}; send one packet per line")]
    TrailingText {
        /// The start of the extra text.
        text: String,
    },
    /// There is no `#` between the code and the fields.
    #[error("missing '#' after the command code, e.g. <FK#J1=0> or <PING#>")]
    MissingHash,
    /// Nothing between `<` and `#`.
    #[error("empty command code; put it between '<' and '#', e.g. <FK#J1=0>")]
    EmptyCode,
    /// The code has characters other than ASCII letters, digits and `_`, or is too long.
    #[error("invalid command code {code:?}: use 1 to {MAX_CODE_LEN} ASCII letters, digits or '_'")]
    InvalidCode {
        /// The start of the code as received.
        code: String,
    },
    /// A field is empty: two commas in a row, or a trailing comma.
    #[error("empty field number {index} (two commas in a row or a trailing comma?)")]
    EmptyField {
        /// 1-based position of the field.
        index: usize,
    },
    /// A field has no `=`.
    #[error("field {field:?} has no '='; write KEY=VALUE")]
    MissingEquals {
        /// The start of the field.
        field: String,
    },
    /// `J1=0,785`: the comma split a decimal number into a field without `=`.
    #[error("comma used as decimal separator in {key}={int},{frac}? use '.' e.g. {key}={int}.{frac}")]
    CommaDecimal {
        /// The key whose value was split.
        key: String,
        /// The digits before the comma.
        int: String,
        /// The digits after the comma.
        frac: String,
    },
    /// A field of the form `=VALUE`.
    #[error("empty key in field {field:?}; write KEY=VALUE")]
    EmptyKey {
        /// The start of the field.
        field: String,
    },
    /// The key has characters other than ASCII letters, digits and `_`, or is too long.
    #[error("invalid key {key:?}: use 1 to {MAX_KEY_LEN} ASCII letters, digits or '_'")]
    InvalidKey {
        /// The start of the key.
        key: String,
    },
    /// A field of the form `KEY=`.
    #[error("empty value for key {key}; write {key}=<number>")]
    EmptyValue {
        /// The (uppercased) key.
        key: String,
    },
    /// The value does not parse as a decimal number.
    #[error(
        "value {value:?} of key {key} is not a number; use digits with '.' as decimal point, e.g. 0.785 or -1.5e-3"
    )]
    NotANumber {
        /// The (uppercased) key.
        key: String,
        /// The start of the value.
        value: String,
    },
    /// The value is `inf`, `nan` or overflows `f64` (e.g. `1e400`).
    #[error(
        "value {value:?} of key {key} is not a finite number; inf, nan and out-of-range values like 1e400 are refused"
    )]
    NonFinite {
        /// The (uppercased) key.
        key: String,
        /// The start of the value.
        value: String,
    },
    /// More than [`MAX_FIELDS`] fields.
    #[error("too many fields: at most {max} per packet")]
    TooManyFields {
        /// The limit.
        max: usize,
    },
    /// The same key appears twice (keys are case-insensitive).
    #[error("duplicate key {key}; each key may appear once per packet")]
    DuplicateKey {
        /// The (uppercased) key.
        key: String,
    },
}

/// Parses one line as a packet. See the module docs for the grammar.
///
/// Whitespace is allowed around the whole packet and around the code, keys, values and
/// separators. Codes and keys are case-insensitive and come back uppercased. `<PING#>`,
/// with no fields, is valid.
pub fn parse_packet(line: &str) -> Result<Packet, PacketError> {
    if line.len() > MAX_PACKET_LEN {
        return Err(PacketError::TooLong {
            len: line.len(),
            max: MAX_PACKET_LEN,
        });
    }
    let raw = line.trim();
    if raw.is_empty() {
        return Err(PacketError::Empty);
    }
    let Some(after_open) = raw.strip_prefix('<') else {
        return Err(PacketError::MissingOpen);
    };
    let Some((inner, after_close)) = after_open.split_once('>') else {
        return Err(PacketError::MissingClose);
    };
    // Whitespace between '>' and the end of the line is tolerated; anything else is not.
    if !after_close.trim().is_empty() {
        return Err(PacketError::TrailingText {
            text: snippet(after_close.trim()),
        });
    }
    let Some((code, body)) = inner.split_once('#') else {
        return Err(PacketError::MissingHash);
    };
    let code = code.trim();
    if code.is_empty() {
        return Err(PacketError::EmptyCode);
    }
    if !is_ident(code, MAX_CODE_LEN) {
        return Err(PacketError::InvalidCode { code: snippet(code) });
    }
    let fields = parse_fields(body)?;
    Ok(Packet {
        code: code.to_ascii_uppercase(),
        fields,
        raw: raw.to_owned(),
    })
}

fn parse_fields(body: &str) -> Result<Vec<Field>, PacketError> {
    let mut fields: Vec<Field> = Vec::new();
    if body.trim().is_empty() {
        return Ok(fields);
    }
    // The raw text of the previous value, to recognise `J1=0,785` when we reach `785`.
    let mut prev_value: Option<&str> = None;
    for (i, part) in body.split(',').enumerate() {
        let part = part.trim();
        if part.is_empty() {
            return Err(PacketError::EmptyField { index: i + 1 });
        }
        let Some((key, value)) = part.split_once('=') else {
            if let (Some(prev), Some(last)) = (prev_value, fields.last())
                && is_digits(part)
                && is_digits(prev.strip_prefix(['-', '+']).unwrap_or(prev))
            {
                return Err(PacketError::CommaDecimal {
                    key: last.key.clone(),
                    int: prev.to_owned(),
                    frac: snippet(part),
                });
            }
            return Err(PacketError::MissingEquals { field: snippet(part) });
        };
        let (key, value) = (key.trim(), value.trim());
        if key.is_empty() {
            return Err(PacketError::EmptyKey { field: snippet(part) });
        }
        if !is_ident(key, MAX_KEY_LEN) {
            return Err(PacketError::InvalidKey { key: snippet(key) });
        }
        let key = key.to_ascii_uppercase();
        if value.is_empty() {
            return Err(PacketError::EmptyValue { key });
        }
        let value_num = parse_number(&key, value)?;
        if fields.iter().any(|f| f.key == key) {
            return Err(PacketError::DuplicateKey { key });
        }
        // Checked before the push so the vector never exceeds the limit.
        if fields.len() >= MAX_FIELDS {
            return Err(PacketError::TooManyFields { max: MAX_FIELDS });
        }
        fields.push(Field { key, value: value_num });
        prev_value = Some(value);
    }
    Ok(fields)
}

fn parse_number(key: &str, text: &str) -> Result<f64, PacketError> {
    // Rust's f64 grammar is what we want (sign, '.', exponent) except that it also takes
    // `inf`, `infinity` and `nan`; those parse fine and are caught by the finiteness check,
    // together with overflow like `1e400`, which Rust rounds to infinity.
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(PacketError::NonFinite {
            key: key.to_owned(),
            value: snippet(text),
        }),
        Err(_) => Err(PacketError::NotANumber {
            key: key.to_owned(),
            value: snippet(text),
        }),
    }
}

fn is_ident(s: &str, max: usize) -> bool {
    !s.is_empty() && s.len() <= max && s.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_')
}

fn is_digits(s: &str) -> bool {
    !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit())
}

/// The start of `s`, cut on a char boundary, so error messages stay short.
fn snippet(s: &str) -> String {
    match s.char_indices().nth(SNIPPET_LEN) {
        Some((cut, _)) => format!("{}...", &s[..cut]),
        None => s.to_owned(),
    }
}

impl Packet {
    /// The value of `key`, compared case-insensitively.
    pub fn get(&self, key: &str) -> Option<f64> {
        self.fields
            .iter()
            .find(|f| f.key.eq_ignore_ascii_case(key))
            .map(|f| f.value)
    }

    /// Formats the packet as `<CODE#KEY=VALUE,...>` (no line terminator).
    ///
    /// Numbers use Rust's shortest round-trip formatting, so parsing the result gives back
    /// the same code and bit-identical finite values. Very large or small magnitudes switch
    /// to exponent form to keep a maximal packet under [`MAX_PACKET_LEN`]. The fields are
    /// written as they are; a hand-built packet with invalid keys or non-finite values
    /// produces a line that [`parse_packet`] rejects.
    pub fn encode(&self) -> String {
        let mut out = String::with_capacity(2 + self.code.len() + 1 + self.fields.len() * 16);
        out.push('<');
        out.push_str(&self.code);
        out.push('#');
        for (i, f) in self.fields.iter().enumerate() {
            if i > 0 {
                out.push(',');
            }
            out.push_str(&f.key);
            out.push('=');
            out.push_str(&format_number(f.value));
        }
        out.push('>');
        out
    }
}

/// Shortest round-trip text for `v`: plain decimal like the paper's `0.785398163397448`
/// when short, exponent form otherwise (plain `1e300` would be 301 digits).
fn format_number(v: f64) -> String {
    let plain = format!("{v}");
    if plain.len() <= 24 { plain } else { format!("{v:e}") }
}

/// Builds an `<ERR#msg>` reply.
///
/// The message is made safe to embed: `<`, `>`, `#` and control characters (CR, LF, tab,
/// ...) become spaces so the reply is one well-formed line, and it is cut to
/// [`MAX_ERROR_MSG_LEN`] characters (with `...`) so a long echo of peer input cannot
/// bloat replies.
pub fn encode_error(msg: &str) -> String {
    let mut out = String::with_capacity(MAX_ERROR_MSG_LEN + 8);
    out.push_str("<ERR#");
    for (n, c) in msg.trim().chars().enumerate() {
        if n == MAX_ERROR_MSG_LEN {
            out.push_str("...");
            break;
        }
        // Only '>' (which would end the packet early) and line breaks are unsafe in the
        // message; brackets become parentheses so quoted packets stay readable.
        out.push(match c {
            '<' => '(',
            '>' => ')',
            c if c.is_control() => ' ',
            c => c,
        });
    }
    out.push('>');
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fields(p: &Packet) -> Vec<(&str, f64)> {
        p.fields.iter().map(|f| (f.key.as_str(), f.value)).collect()
    }

    #[test]
    #[expect(
        clippy::approx_constant,
        reason = "the paper's own literals, which are pi/4 and pi/2 truncated"
    )]
    fn paper_examples() {
        let p = parse_packet("<FK#J1=0.785398163397448,J2=0,J3=-1.5707963267949,J4=0,J5=0,J6=0>").unwrap();
        assert_eq!(p.code, "FK");
        assert_eq!(
            fields(&p),
            [
                ("J1", 0.785398163397448),
                ("J2", 0.0),
                ("J3", -1.5707963267949),
                ("J4", 0.0),
                ("J5", 0.0),
                ("J6", 0.0)
            ]
        );
        let p = parse_packet("<IK#TX=0.25,TY=1,TZ=0.6,RX=0,RY=0,RZ=0>").unwrap();
        assert_eq!(p.code, "IK");
        assert_eq!(p.get("tx"), Some(0.25));
        assert_eq!(p.get("TZ"), Some(0.6));
        assert_eq!(p.get("nope"), None);
    }

    #[test]
    fn accepted_variants() {
        type Case = (&'static str, &'static str, &'static [(&'static str, f64)]);
        let cases: &[Case] = &[
            ("<PING#>", "PING", &[]),
            ("  <ping#  >  ", "PING", &[]),
            ("<FK#J1=12.45, J2=33.25>", "FK", &[("J1", 12.45), ("J2", 33.25)]),
            (
                "\t< fk # j1 = 1 , J_2=-2.5e-3 >\t",
                "FK",
                &[("J1", 1.0), ("J_2", -2.5e-3)],
            ),
            (
                "<A#X=+1,Y=.5,Z=1.,W=1E3>",
                "A",
                &[("X", 1.0), ("Y", 0.5), ("Z", 1.0), ("W", 1e3)],
            ),
            ("<A#X=-0>", "A", &[("X", -0.0)]),
            ("<A#X=1e308>", "A", &[("X", 1e308)]),
            ("<A_1#K9=4.9e-324>", "A_1", &[("K9", 4.9e-324)]),
        ];
        for &(line, code, want) in cases {
            let p = parse_packet(line).unwrap_or_else(|e| panic!("{line:?}: {e}"));
            assert_eq!(p.code, code, "{line:?}");
            assert_eq!(fields(&p), want, "{line:?}");
            assert_eq!(p.raw, line.trim());
        }
    }

    #[test]
    fn rejected_variants() {
        use PacketError as E;
        let long = format!("<A#X={}>", "1".repeat(MAX_PACKET_LEN));
        let many: Vec<String> = (0..=MAX_FIELDS).map(|i| format!("K{i}=1")).collect();
        let many = format!("<A#{}>", many.join(","));
        let max: Vec<String> = (0..MAX_FIELDS).map(|i| format!("K{i}=1")).collect();
        assert!(parse_packet(&format!("<A#{}>", max.join(","))).is_ok());
        let s = |x: &str| x.to_owned();
        let cases: Vec<(&str, PacketError)> = vec![
            (
                &long,
                E::TooLong {
                    len: long.len(),
                    max: MAX_PACKET_LEN,
                },
            ),
            ("", E::Empty),
            ("   ", E::Empty),
            ("FK#J1=0>", E::MissingOpen),
            ("<FK#J1=0", E::MissingClose),
            ("<FK#J1=0> x", E::TrailingText { text: s("x") }),
            ("<FK#J1=0><PING#>", E::TrailingText { text: s("<PING#>") }),
            ("<FK J1=0>", E::MissingHash),
            ("<#J1=0>", E::EmptyCode),
            ("< #>", E::EmptyCode),
            ("<F-K#>", E::InvalidCode { code: s("F-K") }),
            (
                "<ABCDEFGHIJKLMNOPQ#>",
                E::InvalidCode {
                    code: s("ABCDEFGHIJKLMNOPQ"),
                },
            ),
            ("<FK#J1=0,,J2=1>", E::EmptyField { index: 2 }),
            ("<FK#J1=0,>", E::EmptyField { index: 2 }),
            ("<FK#,>", E::EmptyField { index: 1 }),
            ("<FK#J1>", E::MissingEquals { field: s("J1") }),
            ("<FK#J1=1,J2>", E::MissingEquals { field: s("J2") }),
            ("<FK#J1=0.5,785>", E::MissingEquals { field: s("785") }),
            (
                "<FK#J1=0,785>",
                E::CommaDecimal {
                    key: s("J1"),
                    int: s("0"),
                    frac: s("785"),
                },
            ),
            (
                "<FK#J1=-1, 5>",
                E::CommaDecimal {
                    key: s("J1"),
                    int: s("-1"),
                    frac: s("5"),
                },
            ),
            ("<FK#=1>", E::EmptyKey { field: s("=1") }),
            ("<FK#J 1=1>", E::InvalidKey { key: s("J 1") }),
            ("<FK#J-1=1>", E::InvalidKey { key: s("J-1") }),
            ("<FK#ÄÖ=1>", E::InvalidKey { key: s("ÄÖ") }),
            ("<FK#J1=>", E::EmptyValue { key: s("J1") }),
            ("<FK#j1= >", E::EmptyValue { key: s("J1") }),
            (
                "<FK#J1=abc>",
                E::NotANumber {
                    key: s("J1"),
                    value: s("abc"),
                },
            ),
            (
                "<FK#J1=1 2>",
                E::NotANumber {
                    key: s("J1"),
                    value: s("1 2"),
                },
            ),
            (
                "<FK#J1=0x10>",
                E::NotANumber {
                    key: s("J1"),
                    value: s("0x10"),
                },
            ),
            (
                "<FK#J1=1=2>",
                E::NotANumber {
                    key: s("J1"),
                    value: s("1=2"),
                },
            ),
            (
                "<FK#J1=inf>",
                E::NonFinite {
                    key: s("J1"),
                    value: s("inf"),
                },
            ),
            (
                "<FK#J1=-Infinity>",
                E::NonFinite {
                    key: s("J1"),
                    value: s("-Infinity"),
                },
            ),
            (
                "<FK#J1=NaN>",
                E::NonFinite {
                    key: s("J1"),
                    value: s("NaN"),
                },
            ),
            (
                "<FK#J1=1e400>",
                E::NonFinite {
                    key: s("J1"),
                    value: s("1e400"),
                },
            ),
            (&many, E::TooManyFields { max: MAX_FIELDS }),
            ("<FK#J1=1,j1=2>", E::DuplicateKey { key: s("J1") }),
        ];
        for (line, want) in cases {
            let got = parse_packet(line);
            assert_eq!(got, Err(want), "{line:?}");
        }
    }

    #[test]
    fn comma_decimal_message_tells_the_fix() {
        let e = parse_packet("<FK#J1=0,785>").unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("comma used as decimal separator"), "{msg}");
        assert!(msg.contains("J1=0.785"), "{msg}");
    }

    #[test]
    fn snippets_are_bounded() {
        let key = "K".repeat(100);
        let Err(PacketError::InvalidKey { key: k }) = parse_packet(&format!("<A#{key}=1>")) else {
            panic!("expected InvalidKey");
        };
        assert_eq!(k.len(), SNIPPET_LEN + 3);
    }

    #[test]
    fn encode_error_sanitizes_and_bounds() {
        assert_eq!(encode_error("bad <x>#y\r\nz"), "<ERR#bad (x)#y  z>");
        let long = encode_error(&"é".repeat(500));
        assert_eq!(long.chars().count(), "<ERR#>".len() + MAX_ERROR_MSG_LEN + 3);
        // Every PacketError message survives as one line.
        let e = parse_packet("<FK#J1=0,785>").unwrap_err();
        let reply = encode_error(&e.to_string());
        assert!(reply.starts_with("<ERR#comma used"));
        assert_eq!(reply.matches(['<', '>', '#']).count(), 3);
    }

    #[test]
    fn encode_matches_paper_style() {
        let p = parse_packet("<fk#j1=0.785398163397448, j2=0,J3=-1.5707963267949>").unwrap();
        assert_eq!(p.encode(), "<FK#J1=0.785398163397448,J2=0,J3=-1.5707963267949>");
        let p = Packet {
            code: "A".into(),
            fields: vec![Field {
                key: "X".into(),
                value: 1e300,
            }],
            raw: String::new(),
        };
        assert_eq!(p.encode(), "<A#X=1e300>");
    }

    /// xorshift64*: deterministic, dependency-free randomness for the round-trip property.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
        }
        fn below(&mut self, n: u64) -> u64 {
            self.next() % n
        }
        fn ident(&mut self, max: u64) -> String {
            const CH: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_";
            let len = 1 + self.below(max);
            (0..len)
                .map(|_| char::from(CH[self.below(CH.len() as u64) as usize]))
                .collect()
        }
        fn finite(&mut self) -> f64 {
            match self.below(4) {
                0 => (self.below(2001) as f64 - 1000.0) / 8.0,
                1 => (self.next() as f64 / u64::MAX as f64 - 0.5) * std::f64::consts::TAU,
                2 => self.below(1_000_000) as f64,
                _ => loop {
                    let v = f64::from_bits(self.next());
                    if v.is_finite() {
                        break v;
                    }
                },
            }
        }
    }

    #[test]
    fn round_trip_property() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        for _ in 0..2000 {
            let n = rng.below(MAX_FIELDS as u64 + 1) as usize;
            let mut fields: Vec<Field> = Vec::with_capacity(n);
            while fields.len() < n {
                let key = rng.ident(MAX_KEY_LEN as u64);
                if fields.iter().all(|f| f.key != key) {
                    let value = rng.finite();
                    fields.push(Field { key, value });
                }
            }
            let p = Packet {
                code: rng.ident(MAX_CODE_LEN as u64),
                fields,
                raw: String::new(),
            };
            let line = p.encode();
            let q = parse_packet(&line).unwrap_or_else(|e| panic!("{line}: {e}"));
            assert_eq!(q.code, p.code);
            assert_eq!(q.fields.len(), p.fields.len());
            for (a, b) in p.fields.iter().zip(&q.fields) {
                assert_eq!(a.key, b.key);
                assert_eq!(a.value.to_bits(), b.value.to_bits(), "{line}");
            }
            assert_eq!(q.raw, line);
        }
    }
}
