//! Reading a `multipart/form-data` body, as the fake server receives transcription uploads.

/// One field of a form.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FormPart {
    pub name: String,
    pub file_name: Option<String>,
    pub content_type: Option<String>,
    pub data: Vec<u8>,
}

impl FormPart {
    pub fn text(&self) -> String {
        String::from_utf8_lossy(&self.data).into_owned()
    }
}

/// The boundary of a `multipart/form-data; boundary=...` content type.
pub fn boundary(content_type: &str) -> Option<String> {
    let (kind, params) = content_type.split_once(';')?;
    if !kind.trim().eq_ignore_ascii_case("multipart/form-data") {
        return None;
    }
    params.split(';').find_map(|p| {
        let (k, v) = p.split_once('=')?;
        (k.trim() == "boundary").then(|| v.trim().trim_matches('"').to_string())
    })
}

/// The parts of `body`, in order.
pub fn parse(body: &[u8], boundary: &str) -> Vec<FormPart> {
    let delimiter = format!("--{boundary}").into_bytes();
    let mut parts = Vec::new();
    let mut rest = body;
    // Skip the preamble up to the first delimiter.
    let Some(start) = find(rest, &delimiter) else {
        return parts;
    };
    rest = &rest[start + delimiter.len()..];
    while !rest.starts_with(b"--") {
        let rest_body = rest.strip_prefix(b"\r\n").unwrap_or(rest);
        let Some(head_end) = find(rest_body, b"\r\n\r\n") else {
            break;
        };
        let head = String::from_utf8_lossy(&rest_body[..head_end]).into_owned();
        let data_start = head_end + 4;
        let Some(end) = find(&rest_body[data_start..], &delimiter) else {
            break;
        };
        let mut data = &rest_body[data_start..data_start + end];
        data = data.strip_suffix(b"\r\n").unwrap_or(data);
        parts.push(part(&head, data));
        rest = &rest_body[data_start + end + delimiter.len()..];
    }
    parts
}

fn part(head: &str, data: &[u8]) -> FormPart {
    let mut p = FormPart {
        name: String::new(),
        file_name: None,
        content_type: None,
        data: data.to_vec(),
    };
    for line in head.split("\r\n") {
        let Some((k, v)) = line.split_once(':') else {
            continue;
        };
        if k.trim().eq_ignore_ascii_case("content-type") {
            p.content_type = Some(v.trim().to_string());
        } else if k.trim().eq_ignore_ascii_case("content-disposition") {
            for param in v.split(';') {
                if let Some((pk, pv)) = param.split_once('=') {
                    let value = pv.trim().trim_matches('"').to_string();
                    match pk.trim() {
                        "name" => p.name = value,
                        "filename" => p.file_name = Some(value),
                        _ => {}
                    }
                }
            }
        }
    }
    p
}

fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).position(|w| w == needle)
}
