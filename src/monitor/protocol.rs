//! Groot2's monitor protocol as BehaviorTree.CPP 4 speaks it
//! (`loggers/groot2_protocol.h`): ZeroMQ request–reply, each request a 6-byte header
//! (protocol id, request type, a request id) and an optional body, each reply a 22-byte
//! header (the request's header echoed and the tree's 16-byte id) and a payload, or the two
//! frames `error`, message. Numbers are little-endian, as the publisher writes its native
//! integers on the platforms BT.CPP runs on.

use thiserror::Error;

/// The status changes a BT.CPP 4 publisher keeps between two reads; past that it drops
/// the oldest.
pub const KEPT_CHANGES: usize = 1000;

/// The protocol version this module speaks (BT.CPP 4's `kProtocolID`).
pub const PROTOCOL_ID: u8 = 2;
const REQUEST_HEADER: usize = 6;
const REPLY_HEADER: usize = REQUEST_HEADER + 16;

/// What a request asks the publisher.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RequestKind {
    /// The whole tree as XML, with each node's `_uid`.
    FullTree,
    /// Every node's current status.
    Status,
    /// Start (body `start`) or stop (`stop`) keeping every status change.
    ToggleRecording,
    /// The status changes kept since the last such request.
    Transitions,
    /// Stop before a node is ticked (body: the hook as JSON).
    HookInsert,
    /// Take a stop away (body: the node and the position as JSON).
    HookRemove,
    /// Let a stopped node go on, or give it a status (body: JSON).
    BreakpointUnlock,
    /// Take every stop away.
    RemoveAllHooks,
    /// The entries of the blackboards named in the body (`;` between names).
    Blackboard,
}

impl RequestKind {
    fn byte(self) -> u8 {
        match self {
            RequestKind::FullTree => b'T',
            RequestKind::Status => b'S',
            RequestKind::ToggleRecording => b'r',
            RequestKind::Transitions => b't',
            RequestKind::HookInsert => b'I',
            RequestKind::HookRemove => b'R',
            RequestKind::BreakpointUnlock => b'U',
            RequestKind::RemoveAllHooks => b'A',
            RequestKind::Blackboard => b'B',
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            RequestKind::FullTree => "full tree",
            RequestKind::Status => "status",
            RequestKind::ToggleRecording => "toggle recording",
            RequestKind::Transitions => "transitions",
            RequestKind::HookInsert => "breakpoint",
            RequestKind::HookRemove => "breakpoint removal",
            RequestKind::BreakpointUnlock => "breakpoint release",
            RequestKind::RemoveAllHooks => "remove all breakpoints",
            RequestKind::Blackboard => "blackboard",
        }
    }
}

/// A node's status as the publisher reports it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum NodeStatus {
    Idle,
    Running,
    Success,
    Failure,
    Skipped,
}

impl NodeStatus {
    /// BT.CPP's `NodeStatus` value; the status buffer's 10 + status ("idle, after
    /// success") is idle.
    fn from_byte(byte: u8) -> Option<NodeStatus> {
        Some(match byte {
            0 | 11..=13 => NodeStatus::Idle,
            1 => NodeStatus::Running,
            2 => NodeStatus::Success,
            3 => NodeStatus::Failure,
            4 => NodeStatus::Skipped,
            _ => return None,
        })
    }

    /// betr's status for it: a skipped node is shown as idle (it was not ticked).
    pub fn as_status(self) -> crate::bt::Status {
        use crate::bt::Status;
        match self {
            NodeStatus::Idle | NodeStatus::Skipped => Status::Idle,
            NodeStatus::Running => Status::Running,
            NodeStatus::Success => Status::Success,
            NodeStatus::Failure => Status::Failure,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            NodeStatus::Idle => "IDLE",
            NodeStatus::Running => "RUNNING",
            NodeStatus::Success => "SUCCESS",
            NodeStatus::Failure => "FAILURE",
            NodeStatus::Skipped => "SKIPPED",
        }
    }
}

/// A reply that is not what the protocol promises, or the publisher's own error.
#[derive(Debug, Error, PartialEq, Eq)]
pub enum ProtocolError {
    #[error("the reply to a {request} request is not Groot2's: {what}")]
    NotGroot2 { request: &'static str, what: String },
    #[error(
        "the publisher speaks Groot2 protocol version {got}; betr speaks version {PROTOCOL_ID} (BehaviorTree.CPP 4)"
    )]
    Version { got: u8 },
    #[error("the publisher refused a {request} request: {message}")]
    Refused {
        request: &'static str,
        message: String,
    },
    #[error("the {what} payload is {len} bytes, not a whole number of {unit}-byte entries")]
    Ragged {
        what: &'static str,
        len: usize,
        unit: usize,
    },
    #[error("node {uid}'s status byte is {byte}, which is no BehaviorTree.CPP status")]
    Status { uid: u16, byte: u8 },
}

/// One request: its kind, its id (echoed in the reply) and its frames.
#[derive(Clone, Debug)]
pub struct Request {
    pub kind: RequestKind,
    pub id: u32,
    pub body: Option<Vec<u8>>,
}

impl Request {
    pub fn new(kind: RequestKind, id: u32) -> Request {
        Request {
            kind,
            id,
            body: None,
        }
    }

    pub fn with_body(mut self, body: &[u8]) -> Request {
        self.body = Some(body.to_vec());
        self
    }

    /// The request's frames: the header, then the body if any.
    pub fn frames(&self) -> Vec<Vec<u8>> {
        let mut header = Vec::with_capacity(REQUEST_HEADER);
        header.push(PROTOCOL_ID);
        header.push(self.kind.byte());
        header.extend_from_slice(&self.id.to_le_bytes());
        let mut frames = vec![header];
        frames.extend(self.body.clone());
        frames
    }

    /// The reply's payload and the tree id, checked against this request.
    pub fn read_reply<'a>(&self, frames: &'a [&'a [u8]]) -> Result<Reply<'a>, ProtocolError> {
        let request = self.kind.name();
        let Some(first) = frames.first() else {
            return Err(ProtocolError::NotGroot2 {
                request,
                what: "it has no frames".into(),
            });
        };
        if *first == b"error" {
            let message = frames
                .get(1)
                .map(|m| crate::http_text::printable(&String::from_utf8_lossy(m)).into_owned())
                .unwrap_or_default();
            return Err(ProtocolError::Refused { request, message });
        }
        if first.len() != REPLY_HEADER {
            return Err(ProtocolError::NotGroot2 {
                request,
                what: format!(
                    "its first frame is {} bytes, where Groot2's reply header is {REPLY_HEADER}",
                    first.len()
                ),
            });
        }
        if first[0] != PROTOCOL_ID {
            return Err(ProtocolError::Version { got: first[0] });
        }
        let id = u32::from_le_bytes([first[2], first[3], first[4], first[5]]);
        if first[1] != self.kind.byte() || id != self.id {
            return Err(ProtocolError::NotGroot2 {
                request,
                what: format!(
                    "it answers request {id} of type {:?}, not request {} of type {:?}",
                    char::from(first[1]),
                    self.id,
                    char::from(self.kind.byte())
                ),
            });
        }
        let mut tree_id = [0u8; 16];
        tree_id.copy_from_slice(&first[REQUEST_HEADER..]);
        Ok(Reply {
            tree_id,
            payload: frames.get(1).copied(),
        })
    }
}

/// A checked reply.
#[derive(Debug)]
pub struct Reply<'a> {
    /// The publisher's tree: a new id means a new tree (the robot restarted).
    pub tree_id: [u8; 16],
    pub payload: Option<&'a [u8]>,
}

/// A breakpoint before node `uid` is ticked (an interactive pre-tick hook), as the
/// publisher reads it.
pub fn breakpoint_body(uid: u16) -> Vec<u8> {
    serde_json::json!({
        "enabled": true,
        "uid": uid,
        "mode": 0,
        "once": false,
        "desired_status": "SKIPPED",
        "position": 0,
    })
    .to_string()
    .into_bytes()
}

/// The breakpoint before node `uid`, to take away.
pub fn breakpoint_removal_body(uid: u16) -> Vec<u8> {
    serde_json::json!({"uid": uid, "position": 0})
        .to_string()
        .into_bytes()
}

/// Lets node `uid`, stopped at its breakpoint, go on: ticked as usual (`None`) or
/// returning `forced` without being ticked.
pub fn release_body(uid: u16, forced: Option<NodeStatus>) -> Vec<u8> {
    let desired = match forced {
        Some(NodeStatus::Success) => "SUCCESS",
        Some(NodeStatus::Failure) => "FAILURE",
        _ => "SKIPPED",
    };
    serde_json::json!({
        "uid": uid,
        "desired_status": desired,
        "position": 0,
        "remove_when_done": false,
    })
    .to_string()
    .into_bytes()
}

/// The node a breakpoint notification (on the publisher's second port) says stopped: a
/// request header of type `N`, then the node's uid in decimal.
pub fn read_breakpoint_reached(frames: &[&[u8]]) -> Result<u16, ProtocolError> {
    let request = "breakpoint notification";
    let not_groot2 = |what: String| ProtocolError::NotGroot2 { request, what };
    let [header, uid, ..] = frames else {
        return Err(not_groot2(format!("it has {} frames, not 2", frames.len())));
    };
    if header.len() != REQUEST_HEADER || header[1] != b'N' {
        return Err(not_groot2(format!(
            "its header is {} bytes of type {:?}",
            header.len(),
            header.get(1).map(|b| char::from(*b))
        )));
    }
    if header[0] != PROTOCOL_ID {
        return Err(ProtocolError::Version { got: header[0] });
    }
    std::str::from_utf8(uid)
        .ok()
        .and_then(|t| t.trim().parse::<u16>().ok())
        .ok_or_else(|| {
            not_groot2(format!(
                "its node {:?} is not a number",
                String::from_utf8_lossy(uid)
            ))
        })
}

/// The status buffer: (node uid, status) for every node.
pub fn read_statuses(payload: &[u8]) -> Result<Vec<(u16, NodeStatus)>, ProtocolError> {
    entries(payload, "status", 3)?
        .map(|entry| {
            let uid = u16::from_le_bytes([entry[0], entry[1]]);
            NodeStatus::from_byte(entry[2])
                .map(|status| (uid, status))
                .ok_or(ProtocolError::Status {
                    uid,
                    byte: entry[2],
                })
        })
        .collect()
}

/// One blackboard as the publisher exports it: each entry's name and value, the value
/// as the JSON BehaviorTree.CPP converts it to (entries of types with no JSON converter
/// are left out by the publisher).
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Blackboard {
    /// The tree instance it belongs to (the main tree's ID, or a SubTree's path).
    pub name: String,
    pub entries: Vec<(String, String)>,
}

impl Blackboard {
    /// One line: its name and every entry (`Main: goal = 3, target = "red cube"`).
    pub fn describe(&self) -> String {
        let entries: Vec<String> = self
            .entries
            .iter()
            .map(|(k, v)| {
                format!(
                    "{} = {}",
                    crate::http_text::printable(k),
                    crate::http_text::printable(v)
                )
            })
            .collect();
        let entries = if entries.is_empty() {
            "no entries".to_string()
        } else {
            entries.join(", ")
        };
        format!("{}: {entries}", crate::http_text::printable(&self.name))
    }

    /// The value of entry `key`.
    pub fn get(&self, key: &str) -> Option<&str> {
        self.entries
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }
}

/// The blackboards of `now` that are new or differ from those of `before`.
pub fn changed_blackboards<'a>(
    before: &[Blackboard],
    now: &'a [Blackboard],
) -> Vec<&'a Blackboard> {
    now.iter().filter(|b| !before.contains(b)).collect()
}

/// The blackboard payload: MessagePack of `{blackboard: {entry: value}}`.
pub fn read_blackboards(payload: &[u8]) -> Result<Vec<Blackboard>, ProtocolError> {
    let not = |what: String| ProtocolError::NotGroot2 {
        request: RequestKind::Blackboard.name(),
        what,
    };
    let value: serde_json::Value = rmp_serde::from_slice(payload)
        .map_err(|e| not(format!("not MessagePack of JSON values ({e})")))?;
    let serde_json::Value::Object(boards) = value else {
        return Err(not(format!(
            "a {} instead of a map of blackboards",
            kind(&value)
        )));
    };
    boards
        .into_iter()
        .map(|(name, entries)| match entries {
            serde_json::Value::Object(entries) => Ok(Blackboard {
                name,
                entries: entries
                    .into_iter()
                    .map(|(key, value)| (key, value.to_string()))
                    .collect(),
            }),
            // An empty blackboard exports as null.
            serde_json::Value::Null => Ok(Blackboard {
                name,
                entries: Vec::new(),
            }),
            other => Err(not(format!(
                "the blackboard {name:?} is a {} instead of a map of entries",
                kind(&other)
            ))),
        })
        .collect()
}

fn kind(value: &serde_json::Value) -> &'static str {
    match value {
        serde_json::Value::Null => "null",
        serde_json::Value::Bool(_) => "boolean",
        serde_json::Value::Number(_) => "number",
        serde_json::Value::String(_) => "string",
        serde_json::Value::Array(_) => "list",
        serde_json::Value::Object(_) => "map",
    }
}

/// One status change the publisher kept while recording.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Transition {
    /// Microseconds since the recording started.
    pub micros: u64,
    pub uid: u16,
    pub status: NodeStatus,
}

/// The transitions payload: 6 bytes of time, the node's uid, its new status.
pub fn read_transitions(payload: &[u8]) -> Result<Vec<Transition>, ProtocolError> {
    entries(payload, "transitions", 9)?
        .map(|entry| {
            let mut time = [0u8; 8];
            time[..6].copy_from_slice(&entry[..6]);
            let uid = u16::from_le_bytes([entry[6], entry[7]]);
            let status = NodeStatus::from_byte(entry[8]).ok_or(ProtocolError::Status {
                uid,
                byte: entry[8],
            })?;
            Ok(Transition {
                micros: u64::from_le_bytes(time),
                uid,
                status,
            })
        })
        .collect()
}

fn entries<'a>(
    payload: &'a [u8],
    what: &'static str,
    unit: usize,
) -> Result<std::slice::ChunksExact<'a, u8>, ProtocolError> {
    if !payload.len().is_multiple_of(unit) {
        return Err(ProtocolError::Ragged {
            what,
            len: payload.len(),
            unit,
        });
    }
    Ok(payload.chunks_exact(unit))
}

#[cfg(test)]
mod tests {
    #[test]
    fn blackboards_are_read_from_messagepack() {
        let payload = rmp_serde::to_vec(&serde_json::json!({
            "Main": {"target": "red cube", "grasps": 2},
            "Work": null,
        }))
        .unwrap();
        let boards = read_blackboards(&payload).unwrap();
        assert_eq!(
            boards[0].describe(),
            "Main: grasps = 2, target = \"red cube\""
        );
        assert_eq!(boards[0].get("grasps"), Some("2"));
        assert_eq!(boards[1].describe(), "Work: no entries");
        assert_eq!(
            changed_blackboards(&boards, &boards),
            Vec::<&Blackboard>::new()
        );

        let list = rmp_serde::to_vec(&serde_json::json!([1, 2])).unwrap();
        let said = read_blackboards(&list).unwrap_err().to_string();
        assert!(
            said.contains("a list instead of a map of blackboards"),
            "{said}"
        );
        let flat = rmp_serde::to_vec(&serde_json::json!({"Main": 3})).unwrap();
        let said = read_blackboards(&flat).unwrap_err().to_string();
        assert!(said.contains("\"Main\" is a number"), "{said}");
        let said = read_blackboards(b"\xc1").unwrap_err().to_string();
        assert!(said.contains("not MessagePack"), "{said}");
    }

    use super::*;

    fn reply_header(kind: u8, id: u32, protocol: u8) -> Vec<u8> {
        let mut h = vec![protocol, kind];
        h.extend_from_slice(&id.to_le_bytes());
        h.extend_from_slice(&[7; 16]);
        h
    }

    #[test]
    fn a_request_is_the_header_then_its_body() {
        let r = Request::new(RequestKind::ToggleRecording, 0x0403_0201).with_body(b"start");
        assert_eq!(
            r.frames(),
            vec![vec![2, b'r', 1, 2, 3, 4], b"start".to_vec()]
        );
        assert_eq!(Request::new(RequestKind::Status, 9).frames().len(), 1);
    }

    #[test]
    fn a_reply_is_checked_against_its_request() {
        let r = Request::new(RequestKind::Status, 77);
        let header = reply_header(b'S', 77, 2);
        let frames: Vec<&[u8]> = vec![&header, &[1, 0, 2]];
        let reply = r.read_reply(&frames).expect("a right reply");
        assert_eq!(reply.tree_id, [7; 16]);
        assert_eq!(reply.payload, Some(&[1u8, 0, 2][..]));

        let other = reply_header(b'S', 78, 2);
        let err = r.read_reply(&[&other]).unwrap_err();
        assert!(err.to_string().contains("request 78"), "{err}");
        let v3 = reply_header(b'S', 77, 3);
        assert_eq!(
            r.read_reply(&[&v3]).unwrap_err(),
            ProtocolError::Version { got: 3 }
        );
        let short: &[u8] = b"HTTP/1.1 400";
        let err = r.read_reply(&[short]).unwrap_err();
        assert!(err.to_string().contains("12 bytes"), "{err}");
        let refused = r
            .read_reply(&[b"error", b"Request not recognized\x1b[2J"])
            .unwrap_err();
        assert_eq!(
            refused.to_string(),
            "the publisher refused a status request: Request not recognized\\u{1b}[2J"
        );
    }

    #[test]
    fn breakpoints_are_written_and_their_notifications_read_as_bt_cpp_does() {
        let hook: serde_json::Value = serde_json::from_slice(&breakpoint_body(7)).expect("JSON");
        assert_eq!(hook["uid"], 7);
        assert_eq!(hook["mode"], 0, "interactive");
        assert_eq!(hook["position"], 0, "before the tick");
        let release: serde_json::Value =
            serde_json::from_slice(&release_body(7, Some(NodeStatus::Failure))).expect("JSON");
        assert_eq!(release["desired_status"], "FAILURE");
        let go_on: serde_json::Value =
            serde_json::from_slice(&release_body(7, None)).expect("JSON");
        assert_eq!(go_on["desired_status"], "SKIPPED");
        assert_eq!(
            read_breakpoint_reached(&[&[2, b'N', 1, 0, 0, 0], b"12"]),
            Ok(12)
        );
        assert_eq!(
            read_breakpoint_reached(&[&[3, b'N', 1, 0, 0, 0], b"12"]),
            Err(ProtocolError::Version { got: 3 })
        );
        assert!(read_breakpoint_reached(&[&[2, b'N', 1, 0, 0, 0], b"x"]).is_err());
        assert!(read_breakpoint_reached(&[&[2, b'N', 1, 0, 0, 0]]).is_err());
    }

    #[test]
    fn statuses_and_transitions_are_read_whole_or_refused() {
        assert_eq!(
            read_statuses(&[1, 0, 1, 2, 0, 12]).unwrap(),
            vec![(1, NodeStatus::Running), (2, NodeStatus::Idle)]
        );
        assert!(matches!(
            read_statuses(&[1, 0]),
            Err(ProtocolError::Ragged { len: 2, .. })
        ));
        assert_eq!(
            read_statuses(&[5, 0, 9]).unwrap_err(),
            ProtocolError::Status { uid: 5, byte: 9 }
        );
        let t = read_transitions(&[0x10, 0x27, 0, 0, 0, 0, 3, 0, 3]).unwrap();
        assert_eq!(
            t,
            vec![Transition {
                micros: 10_000,
                uid: 3,
                status: NodeStatus::Failure
            }]
        );
        assert!(read_transitions(&[0; 10]).is_err());
    }
}
