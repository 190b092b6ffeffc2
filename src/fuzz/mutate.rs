//! Mutations of an input: bit flips and byte changes, insertions of the target's grammar
//! tokens and of awkward text (multi-byte and combining characters, control characters,
//! huge numbers, NaN), deletions and duplications of ranges, splices with another seed,
//! deep nesting with the target's brackets, and long repetitions.

use super::rng::Rng;

/// Inputs are cut to this length after mutation.
pub const MAX_LEN: usize = 1 << 20;

/// Tokens every target gets besides its own: punctuation of the grammars betr reads,
/// awkward characters and numbers.
const GENERIC: &[&str] = &[
    "(",
    ")",
    "&",
    "|",
    "~",
    "\"",
    "'",
    "?",
    "!",
    "\n",
    "\r\n",
    "\r",
    "  ",
    "\t",
    "#",
    "{",
    "}",
    "[",
    "]",
    "<",
    ">",
    "=",
    ",",
    ":",
    ";",
    "\\",
    "\0",
    "\u{7f}",
    "\u{85}",
    "é",
    "e\u{301}",
    "\u{301}\u{301}\u{301}",
    "\u{200b}",
    "\u{feff}",
    "\u{202e}",
    "\u{2028}",
    "😀",
    "𝔘𝔫𝔦",
    "日本語",
    "\u{fffd}",
    "18446744073709551616",
    "99999999999999999999999999999999",
    "4294967295",
    "4294967296",
    "-9223372036854775809",
    "1e309",
    "-1e309",
    "1.7976931348623157e308",
    "5e-324",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "-0",
    "0x1F",
    "",
];

/// Numbers that replace a run of digits.
const NUMBERS: &[&str] = &[
    "0",
    "-1",
    "1",
    "255",
    "256",
    "65535",
    "65536",
    "2147483647",
    "2147483648",
    "4294967295",
    "4294967296",
    "9223372036854775807",
    "18446744073709551615",
    "18446744073709551616",
    "1e308",
    "1e309",
    "NaN",
    "-0.0",
    "0.000000000000000000000000001",
];

/// How often a nesting mutation repeats its brackets: around the parsers' limits and far
/// beyond them.
const DEPTHS: &[usize] = &[2, 10, 100, 127, 128, 129, 255, 256, 257, 1000, 5000, 20_000];

/// What a target gives the mutator.
pub struct Grammar<'a> {
    /// Tokens of the target's format (keywords, keys, tags).
    pub tokens: &'a [String],
    /// Opening and closing text of one level of nesting.
    pub brackets: &'a [(String, String)],
    /// Inputs to splice from.
    pub seeds: &'a [Vec<u8>],
    /// Keep insertions at character boundaries (text formats).
    pub text: bool,
}

impl Grammar<'_> {
    /// Apply one random mutation to `data`.
    pub fn mutate(&self, data: &mut Vec<u8>, rng: &mut Rng) {
        match rng.below(16) {
            0 => {
                if !data.is_empty() {
                    // Text keeps an ASCII byte ASCII, mostly.
                    let i = rng.below(data.len());
                    let bits = if self.text && data[i] < 0x80 && rng.chance(90) {
                        7
                    } else {
                        8
                    };
                    data[i] ^= 1 << rng.below(bits);
                }
            }
            1 => {
                if !data.is_empty() {
                    let i = rng.below(data.len());
                    let ascii: &[u8] = &[0, 0x7f, b' ', b'0', b'"', b'\n'];
                    let any: &[u8] = &[0, 0xff, 0x7f, 0x80, b' ', b'0', 0xc3];
                    let bytes = if self.text && rng.chance(90) {
                        ascii
                    } else {
                        any
                    };
                    data[i] = *rng.pick(bytes).unwrap_or(&0);
                }
            }
            2..=4 => {
                let token = self.token(rng);
                let at = self.position(data, rng);
                insert(data, at, &token);
            }
            5 | 6 => {
                let at = self.position(data, rng);
                let len = rng.small(data.len().saturating_sub(at));
                let end = self.boundary(data, at + len);
                data.drain(at..end.max(at));
            }
            7 => {
                let at = self.position(data, rng);
                let len = rng.small(data.len().saturating_sub(at));
                let end = self.boundary(data, at + len);
                let copy = data[at..end.max(at)].to_vec();
                let to = self.position(data, rng);
                insert(data, to, &copy);
            }
            8 => {
                let count = rng.small(16);
                let mask = if self.text && rng.chance(90) {
                    0x7f
                } else {
                    0xff
                };
                let bytes: Vec<u8> = (0..count).map(|_| (rng.next_u64() & mask) as u8).collect();
                let at = self.position(data, rng);
                insert(data, at, &bytes);
            }
            9 => {
                let c = random_char(rng);
                let at = self.position(data, rng);
                insert(data, at, c.encode_utf8(&mut [0; 4]).as_bytes());
            }
            10 => self.splice(data, rng),
            11 => self.replace_number(data, rng),
            12 => {
                let at = self.position(data, rng);
                data.truncate(at);
            }
            13 => self.nest(data, rng),
            14 if rng.chance(25) => {
                // A long input: a range repeated many times (rarely: it is slow to read).
                let at = self.position(data, rng);
                let len = 1 + rng.small(64);
                let end = self.boundary(data, (at + len).min(data.len()));
                let chunk = data[at..end.max(at)].to_vec();
                if !chunk.is_empty() {
                    let times = rng.between(100, 20_000.min(MAX_LEN / chunk.len()));
                    let long = chunk.repeat(times);
                    insert(data, end.max(at), &long);
                }
            }
            14 => {
                let token = self.token(rng);
                let at = self.position(data, rng);
                insert(data, at, &token);
            }
            _ => {
                // Swap a line with another (line-oriented formats).
                let lines: Vec<&[u8]> = data.split(|b| *b == b'\n').collect();
                if lines.len() > 1 {
                    let (a, b) = (rng.below(lines.len()), rng.below(lines.len()));
                    let mut out: Vec<&[u8]> = lines.clone();
                    out.swap(a, b);
                    *data = out.join(&b'\n');
                }
            }
        }
        data.truncate(MAX_LEN);
    }

    fn token(&self, rng: &mut Rng) -> Vec<u8> {
        if !self.tokens.is_empty() && rng.chance(60) {
            return rng
                .pick(self.tokens)
                .map_or_else(Vec::new, |t| t.as_bytes().to_vec());
        }
        rng.pick(GENERIC)
            .map_or_else(Vec::new, |t| t.as_bytes().to_vec())
    }

    /// A random position, moved to the next character boundary for text.
    fn position(&self, data: &[u8], rng: &mut Rng) -> usize {
        let at = rng.below(data.len() + 1);
        self.boundary(data, at)
    }

    fn boundary(&self, data: &[u8], mut at: usize) -> usize {
        at = at.min(data.len());
        if self.text {
            while at < data.len() && data[at] & 0xC0 == 0x80 {
                at += 1;
            }
        }
        at
    }

    /// Insert a range of another seed, or replace the tail with one.
    fn splice(&self, data: &mut Vec<u8>, rng: &mut Rng) {
        let Some(other) = rng.pick(self.seeds) else {
            return;
        };
        let from = self.boundary(other, rng.below(other.len() + 1));
        let len = rng.small(other.len().saturating_sub(from).max(1) * 4);
        let to = self.boundary(other, from + len);
        let piece = other[from..to.max(from)].to_vec();
        let at = self.position(data, rng);
        if rng.chance(50) {
            data.truncate(at);
            data.extend_from_slice(&piece);
        } else {
            insert(data, at, &piece);
        }
    }

    /// Replace a run of ASCII digits with an awkward number.
    fn replace_number(&self, data: &mut Vec<u8>, rng: &mut Rng) {
        let starts: Vec<usize> = (0..data.len())
            .filter(|&i| data[i].is_ascii_digit() && (i == 0 || !data[i - 1].is_ascii_digit()))
            .collect();
        let Some(&start) = rng.pick(&starts) else {
            return;
        };
        let end = (start..data.len())
            .find(|&i| !data[i].is_ascii_digit() && data[i] != b'.')
            .unwrap_or(data.len());
        let number = rng.pick(NUMBERS).copied().unwrap_or("0");
        data.splice(start..end, number.bytes());
    }

    /// Wrap a range in many levels of one of the target's brackets.
    fn nest(&self, data: &mut Vec<u8>, rng: &mut Rng) {
        let Some((open, close)) = rng.pick(self.brackets) else {
            return;
        };
        let depth = rng.pick(DEPTHS).copied().unwrap_or(2);
        let a = self.position(data, rng);
        let b = self.position(data, rng);
        let (a, b) = (a.min(b), a.max(b));
        let mut out = Vec::with_capacity(data.len() + depth * (open.len() + close.len()));
        out.extend_from_slice(&data[..a]);
        for _ in 0..depth {
            out.extend_from_slice(open.as_bytes());
        }
        out.extend_from_slice(&data[a..b]);
        // Sometimes the brackets are left unbalanced.
        let closing = if rng.chance(80) {
            depth
        } else {
            rng.below(depth + 2)
        };
        for _ in 0..closing {
            out.extend_from_slice(close.as_bytes());
        }
        out.extend_from_slice(&data[b..]);
        *data = out;
    }
}

fn insert(data: &mut Vec<u8>, at: usize, bytes: &[u8]) {
    let at = at.min(data.len());
    data.splice(at..at, bytes.iter().copied());
}

/// A random character: mostly ASCII, else combining marks, control characters, wide and
/// astral characters.
pub fn random_char(rng: &mut Rng) -> char {
    let code = match rng.below(8) {
        0..=2 => 0x20 + rng.below(0x5f) as u32,
        3 => rng.below(0x20) as u32,
        4 => 0x300 + rng.below(0x70) as u32,
        5 => 0x80 + rng.below(0x780) as u32,
        6 => 0x1_0000 + rng.below(0x1_0000) as u32,
        _ => rng.below(0x11_0000) as u32,
    };
    char::from_u32(code).unwrap_or('\u{fffd}')
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mutations_stay_bounded_and_text_stays_mostly_text() {
        let tokens = vec!["sequence".to_string()];
        let brackets = vec![("(".to_string(), ")".to_string())];
        let seeds = vec![b"A & (B | ~C)".to_vec(), "é | ü".as_bytes().to_vec()];
        let g = Grammar {
            tokens: &tokens,
            brackets: &brackets,
            seeds: &seeds,
            text: true,
        };
        let mut valid = 0;
        for i in 0..2000 {
            let mut rng = Rng::for_input(1, i);
            let mut data = seeds[(i % 2) as usize].clone();
            for _ in 0..4 {
                g.mutate(&mut data, &mut rng);
            }
            assert!(data.len() <= MAX_LEN);
            valid += usize::from(std::str::from_utf8(&data).is_ok());
        }
        assert!(valid > 1700, "{valid} of 2000 stayed UTF-8");
    }
}
