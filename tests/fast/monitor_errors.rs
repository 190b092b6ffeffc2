//! `betr monitor --print` against what is not a Groot2 publisher: a port no one listens on,
//! a server that is not ZeroMQ, a ZeroMQ server that is not Groot2, a protocol version
//! betr does not know, a tree description that cannot be read. Each is a clear message
//! naming what was expected and what came, and an error exit when the time is up.

#![allow(clippy::unwrap_used)] // tests may panic on what they check
use crate::support;

use std::io::Write;
use std::net::TcpListener;

use support::cli::{betr, text, tmp};
use zeromq::{RepSocket, Socket as _, SocketRecv as _, SocketSend as _, ZmqMessage};

fn monitor(name: &str, port: u16) -> std::process::Output {
    let dir = tmp(name);
    betr(
        &dir,
        &[
            "monitor",
            "--print",
            "--for",
            "2",
            &format!("127.0.0.1:{port}"),
        ],
    )
}

/// A ZeroMQ REP server on a free port answering every request with `reply(request)`.
fn zmq_server(reply: fn(&[u8]) -> Vec<Vec<u8>>) -> u16 {
    let port = TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let (ready, bound) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .unwrap();
        runtime.block_on(async move {
            let mut socket = RepSocket::new();
            socket
                .bind(&format!("tcp://127.0.0.1:{port}"))
                .await
                .unwrap();
            ready.send(()).unwrap();
            while let Ok(request) = socket.recv().await {
                let header = request.get(0).map(|f| f.to_vec()).unwrap_or_default();
                let mut frames = reply(&header).into_iter().map(bytes::Bytes::from);
                let mut message = ZmqMessage::from(frames.next().unwrap());
                for frame in frames {
                    message.push_back(frame);
                }
                if socket.send(message).await.is_err() {
                    return;
                }
            }
        });
    });
    bound.recv().unwrap();
    port
}

/// A Groot2 reply header for `request` with protocol `version`.
fn header(request: &[u8], version: u8) -> Vec<u8> {
    let mut h = request.to_vec();
    h[0] = version;
    h.extend_from_slice(&[9; 16]);
    h
}

fn refused(out: &std::process::Output, wanted: &str) {
    let said = text(out);
    assert_eq!(out.status.code(), Some(2), "{said}");
    assert!(said.contains(wanted), "wanted {wanted:?} in:\n{said}");
}

#[test]
fn a_port_no_one_listens_on_is_named() {
    let port = TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let out = monitor("monitor-nobody", port);
    refused(
        &out,
        &format!("error: no Groot2 publisher answers at 127.0.0.1:{port}: Connection refused"),
    );
}

#[test]
fn a_server_that_is_not_zeromq_is_refused() {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = listener.local_addr().unwrap().port();
    std::thread::spawn(move || {
        for stream in listener.incoming() {
            let Ok(mut stream) = stream else { return };
            let _ = stream.write_all(b"HTTP/1.1 400 Bad Request\r\n\r\n");
        }
    });
    let out = monitor("monitor-http", port);
    refused(
        &out,
        &format!("127.0.0.1:{port} accepts connections but not ZeroMQ's greeting"),
    );
}

#[test]
fn a_zeromq_server_that_is_not_groot2_is_refused() {
    let port = zmq_server(|_| vec![b"hello".to_vec()]);
    refused(
        &monitor("monitor-not-groot2", port),
        "the reply to a full tree request is not Groot2's: its first frame is 5 bytes, where Groot2's reply header is 22",
    );
}

#[test]
fn another_protocol_version_is_named() {
    let port = zmq_server(|request| vec![header(request, 3), b"<root/>".to_vec()]);
    refused(
        &monitor("monitor-version", port),
        "the publisher speaks Groot2 protocol version 3; betr speaks version 2",
    );
}

#[test]
fn an_unreadable_tree_is_refused_with_the_line() {
    let port = zmq_server(|request| {
        vec![
            header(request, 2),
            b"<root BTCPP_format=\"4\">\n<BehaviorTree ID=\"M\">\n<Sequence name=\"s\"/>\n</BehaviorTree>\n</root>".to_vec(),
        ]
    });
    refused(
        &monitor("monitor-bad-tree", port),
        "line 3: <Sequence> has no _uid",
    );
}
