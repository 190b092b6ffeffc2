//! Fetching a description from a small source archive served by a package index on
//! 127.0.0.1: the real pip downloads it (the archive builds its metadata with an in-tree
//! backend, so nothing else is needed from the index), betr checks and extracts it.

use std::io::{BufRead, BufReader, Write};
use std::net::{TcpListener, TcpStream};

use sha2::{Digest, Sha256};

use super::*;

struct Quiet;
impl Progress for Quiet {
    fn stage(&mut self, _: &str) {}
    fn bytes(&mut self, _: u64, _: u64) {}
}

/// Records the stages and the last byte count it was told.
#[derive(Default)]
struct Seen {
    stages: Vec<String>,
    last: Option<(u64, u64)>,
}
impl Progress for Seen {
    fn stage(&mut self, message: &str) {
        self.stages.push(message.to_string());
    }
    fn bytes(&mut self, done: u64, total: u64) {
        self.last = Some((done, total));
    }
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("betr-desc-{name}-{}", std::process::id()));
    let _ = fs::remove_dir_all(&d);
    fs::create_dir_all(&d).unwrap();
    d
}

const BACKEND: &str = r#"import os
def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    d = os.path.join(metadata_directory, "tiny_robots-1.0.dist-info")
    os.makedirs(d)
    with open(os.path.join(d, "METADATA"), "w") as f:
        f.write("Metadata-Version: 2.1\nName: tiny-robots\nVersion: 1.0\n")
    return "tiny_robots-1.0.dist-info"
def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    raise RuntimeError("only the metadata is needed")
"#;

/// `tiny-robots-1.0.tar.gz`: an sdist holding `data/arm_description` and another folder.
fn archive(with_licence: bool) -> Vec<u8> {
    let mut files: Vec<(&str, &[u8])> =
        vec![
        (
            "PKG-INFO",
            b"Metadata-Version: 2.1\nName: tiny-robots\nVersion: 1.0\n",
        ),
        (
            "pyproject.toml",
            b"[build-system]\nrequires = []\nbuild-backend = \"backend\"\nbackend-path = [\".\"]\n",
        ),
        ("backend.py", BACKEND.as_bytes()),
        ("data/arm_description/urdf/arm.urdf", b"<robot name=\"arm\"/>\n"),
        ("data/arm_description/meshes/coarse/link.stl", &[7u8; 3000]),
        ("data/other_description/urdf/other.urdf", b"<robot/>\n"),
    ];
    if with_licence {
        files.push(("data/arm_description/license.dat", b"BSD\n"));
    }
    let gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    let mut tar = tar::Builder::new(gz);
    for (name, bytes) in files {
        let mut header = tar::Header::new_gnu();
        header.set_size(bytes.len() as u64);
        header.set_mode(0o644);
        header.set_cksum();
        tar.append_data(&mut header, format!("tiny-robots-1.0/{name}"), bytes)
            .unwrap();
    }
    tar.into_inner().unwrap().finish().unwrap()
}

fn sha(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

fn spec_for(bytes: &[u8], sha256: Option<&str>) -> DescriptionSpec {
    DescriptionSpec {
        name: "tiny-arm",
        description: "test arm",
        requirement: "tiny-robots==1.0",
        archive: "tiny-robots-1.0.tar.gz",
        size: bytes.len() as u64,
        sha256: Box::leak(
            sha256
                .map_or_else(|| sha(bytes), str::to_string)
                .into_boxed_str(),
        ),
        folder: "tiny-robots-1.0/data/arm_description",
        package: "arm_description",
        dir_name: "arm_description-tiny-robots-1.0",
        urdf: "urdf/arm.urdf",
        licence: "license.dat",
    }
}

/// A package index on 127.0.0.1 serving `archive`; with `cut`, the archive's answer
/// announces its whole length and stops halfway. Returns the index URL.
fn serve(archive: Vec<u8>, cut: bool) -> String {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = listener.local_addr().unwrap().port();
    let digest = sha(&archive);
    std::thread::spawn(move || {
        for stream in listener.incoming().flatten() {
            answer(stream, &archive, &digest, cut);
        }
    });
    format!("http://127.0.0.1:{port}/simple/")
}

fn answer(mut stream: TcpStream, archive: &[u8], digest: &str, cut: bool) {
    let mut reader = BufReader::new(stream.try_clone().unwrap());
    let mut request = String::new();
    if reader.read_line(&mut request).is_err() {
        return;
    }
    loop {
        let mut line = String::new();
        if reader.read_line(&mut line).map_or(true, |n| n == 0) || line == "\r\n" {
            break;
        }
    }
    let path = request.split_whitespace().nth(1).unwrap_or("/").to_string();
    let (status, kind, body): (&str, &str, Vec<u8>) = if path.starts_with("/simple/tiny-robots") {
        let page = format!(
            "<!DOCTYPE html><html><body><a href=\"/files/tiny-robots-1.0.tar.gz#sha256={digest}\">tiny-robots-1.0.tar.gz</a></body></html>"
        );
        ("200 OK", "text/html", page.into_bytes())
    } else if path == "/files/tiny-robots-1.0.tar.gz" {
        ("200 OK", "application/octet-stream", archive.to_vec())
    } else {
        ("404 Not Found", "text/plain", b"not here".to_vec())
    };
    let head = format!(
        "HTTP/1.1 {status}\r\nContent-Type: {kind}\r\nContent-Length: {}\r\nConnection: close\r\n\r\n",
        body.len()
    );
    let sent = if cut && kind == "application/octet-stream" {
        &body[..body.len() / 2]
    } else {
        &body[..]
    };
    let _ = stream.write_all(head.as_bytes());
    let _ = stream.write_all(sent);
    let _ = stream.flush();
}

/// What a fetch left in the cache, but the lock files.
fn leftovers(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| !n.ends_with(".lock"))
        .collect();
    names.sort();
    names
}

#[test]
fn only_the_description_folder_is_installed_and_later_calls_need_no_index() {
    let root = scratch("ok");
    let bytes = archive(true);
    let spec = spec_for(&bytes, None);
    let url = serve(bytes.clone(), false);
    let pip = Pip {
        python: "python3",
        index_url: Some(&url),
    };
    let mut seen = Seen::default();
    let path = fetch_description(&spec, &root, pip, &mut seen).unwrap();
    assert_eq!(path, root.join("arm_description-tiny-robots-1.0"));
    assert_eq!(
        fs::read_to_string(spec.urdf_in(&path)).unwrap(),
        "<robot name=\"arm\"/>\n"
    );
    assert_eq!(fs::read(path.join("license.dat")).unwrap(), b"BSD\n");
    assert_eq!(
        fs::metadata(path.join("meshes/coarse/link.stl"))
            .unwrap()
            .len(),
        3000
    );
    let mut kept: Vec<String> = fs::read_dir(&path)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    kept.sort();
    assert_eq!(kept, ["license.dat", "meshes", "urdf"]);
    assert_eq!(leftovers(&root), ["arm_description-tiny-robots-1.0"]);
    assert_eq!(seen.last, Some((spec.size, spec.size)));
    assert!(
        seen.stages[0].contains("tiny-robots==1.0"),
        "{:?}",
        seen.stages
    );

    // Installed: no index is asked again (this one answers nothing).
    let offline = Pip {
        python: "python3",
        index_url: Some("http://127.0.0.1:9/simple/"),
    };
    assert_eq!(
        ensure_description(&spec, &root, offline, &mut Quiet).unwrap(),
        path
    );
    fs::remove_dir_all(&root).unwrap();
}

#[test]
fn a_download_cut_off_midway_installs_nothing() {
    let root = scratch("cut");
    let bytes = archive(true);
    let spec = spec_for(&bytes, None);
    let url = serve(bytes, true);
    let pip = Pip {
        python: "python3",
        index_url: Some(&url),
    };
    let err = fetch_description(&spec, &root, pip, &mut Quiet).unwrap_err();
    assert!(matches!(err, FetchError::Pip { .. }), "{err}");
    assert!(err.to_string().contains("tiny-robots==1.0"), "{err}");
    assert!(leftovers(&root).is_empty(), "{:?}", leftovers(&root));
    fs::remove_dir_all(&root).unwrap();
}

#[test]
fn a_wrong_checksum_or_a_missing_licence_installs_nothing() {
    let root = scratch("bad");
    let bytes = archive(true);
    let url = serve(bytes.clone(), false);
    let pip = Pip {
        python: "python3",
        index_url: Some(&url),
    };
    let wrong = spec_for(&bytes, Some(&"0".repeat(64)));
    let err = fetch_description(&wrong, &root, pip, &mut Quiet).unwrap_err();
    assert!(matches!(err, FetchError::Hash { .. }), "{err}");
    assert!(err.to_string().contains("tiny-robots-1.0.tar.gz"), "{err}");
    assert!(leftovers(&root).is_empty(), "{:?}", leftovers(&root));

    let unlicensed = archive(false);
    let url = serve(unlicensed.clone(), false);
    let pip = Pip {
        python: "python3",
        index_url: Some(&url),
    };
    let spec = spec_for(&unlicensed, None);
    let err = fetch_description(&spec, &root, pip, &mut Quiet).unwrap_err();
    assert!(
        err.to_string()
            .contains("no tiny-robots-1.0/data/arm_description/license.dat inside"),
        "{err}"
    );
    assert!(leftovers(&root).is_empty(), "{:?}", leftovers(&root));
    fs::remove_dir_all(&root).unwrap();
}

#[test]
fn the_yumi_is_known_by_name() {
    assert_eq!(find_description("yumi"), Some(&YUMI_DESCRIPTION));
    assert!(find_description("r2d2").is_none());
    assert_eq!(YUMI_DESCRIPTION.project(), "rtb-data");
    assert!(YUMI_DESCRIPTION.folder.ends_with(YUMI_DESCRIPTION.package));
}
