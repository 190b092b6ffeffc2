//! BehaviorTree.CPP in tests, through its Python bindings (`behaviortreepy`, installed by
//! scripts/btcpp-venv.sh into a virtual environment under target/): the venv's python, and
//! a tree ticked under Groot2's publisher (scripts/btcpp_publisher.py) for the monitor.

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};

use super::verify::root;

/// The venv's python, installed through the script when missing; a failed install fails
/// the test with the script's reason.
pub fn python() -> PathBuf {
    let target = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .parent()
        .unwrap()
        .to_path_buf();
    let venv = target.join("btcpp-venv");
    let out = Command::new("bash")
        .arg(root().join("scripts/btcpp-venv.sh"))
        .arg(&venv)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "scripts/btcpp-venv.sh could not install behaviortreepy into {}: {}",
        venv.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    let python = PathBuf::from(String::from_utf8_lossy(&out.stdout).trim());
    assert!(python.exists(), "{}", python.display());
    python
}

/// A port free on every interface whose next port is free too (the benchmark's).
pub fn free_port_pair() -> u16 {
    betr::bench::monitor::free_port_pair().unwrap()
}

/// A BT.CPP tree published on a port, waiting for [`Publisher::go`] to tick.
pub struct Publisher {
    child: Child,
    stdin: Option<ChildStdin>,
    stdout: BufReader<ChildStdout>,
    pub port: u16,
}

impl Publisher {
    /// Starts the publisher on `port`; `ticks` 0 ticks until [`Publisher::stop`].
    pub fn start(python: &Path, port: u16, ticks: u32) -> Publisher {
        let mut child = Command::new(python)
            .arg(root().join("scripts/btcpp_publisher.py"))
            .arg(port.to_string())
            .arg(ticks.to_string())
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .unwrap();
        let stdin = child.stdin.take();
        let mut stdout = BufReader::new(child.stdout.take().unwrap());
        let mut line = String::new();
        stdout.read_line(&mut line).unwrap();
        assert_eq!(
            line.trim(),
            format!("ready {port}"),
            "the publisher did not start"
        );
        Publisher {
            child,
            stdin,
            stdout,
            port,
        }
    }

    /// Starts ticking.
    pub fn go(&mut self) {
        let stdin = self.stdin.as_mut().expect("the publisher is waiting");
        stdin.write_all(b"go\n").unwrap();
        stdin.flush().unwrap();
    }

    /// Stops a publisher that ticks until told (closes its input).
    pub fn stop(&mut self) {
        self.stdin = None;
    }

    /// The status changes BT.CPP's own logger saw, in order: (node name, old, new). Waits
    /// for the ticks to end and the publisher to exit.
    pub fn seen(mut self) -> Vec<(String, String, String)> {
        self.stdin = None;
        let mut line = String::new();
        self.stdout.read_line(&mut line).unwrap();
        let status = self.child.wait().unwrap();
        assert!(status.success(), "the publisher failed: {status}");
        serde_json::from_str(&line).unwrap_or_else(|e| panic!("{e}: {line}"))
    }
}

impl Drop for Publisher {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
