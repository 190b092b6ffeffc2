//! One connection to a Groot2 publisher: a ZeroMQ REQ socket, each request answered
//! within a time limit or the connection counts as lost (a REQ socket that missed its
//! reply cannot ask again, so a lost connection is dropped and made anew).

use std::time::{Duration, SystemTime, UNIX_EPOCH};

use thiserror::Error;
use zeromq::{
    ReqSocket, Socket as _, SocketOptions, SocketRecv as _, SocketSend as _, SubSocket, ZmqMessage,
};

use super::protocol::{self, NodeStatus, ProtocolError, Request, RequestKind, Transition};
use super::tree::{TreeError, WatchedTree};

/// Where a publisher listens: a host and its request port (BT.CPP's default 1667).
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct Address {
    pub host: String,
    pub port: u16,
}

/// Groot2's default port.
pub const DEFAULT_PORT: u16 = 1667;

impl Address {
    /// `HOST`, `HOST:PORT` or `:PORT`; an IPv6 host in brackets (`[::1]:1667`).
    pub fn parse(text: &str) -> Result<Address, AddressError> {
        let text = text.trim();
        let (host, port) = match text.rsplit_once(':') {
            Some((host, port)) if !host.ends_with(':') || host.starts_with('[') => {
                let port = port.parse::<u16>().ok().filter(|p| *p > 0).ok_or_else(|| {
                    AddressError::Port {
                        text: text.to_string(),
                        port: port.to_string(),
                    }
                })?;
                (host, port)
            }
            _ => (text, DEFAULT_PORT),
        };
        let host = if host.is_empty() { "127.0.0.1" } else { host };
        if host.chars().any(|c| c.is_whitespace() || c == '/') {
            return Err(AddressError::Shape(text.to_string()));
        }
        Ok(Address {
            host: host.to_string(),
            port,
        })
    }

    fn endpoint(&self) -> String {
        format!("tcp://{}:{}", self.host, self.port)
    }
}

impl TryFrom<String> for Address {
    type Error = AddressError;
    fn try_from(text: String) -> Result<Address, AddressError> {
        Address::parse(&text)
    }
}

impl From<Address> for String {
    fn from(address: Address) -> String {
        address.to_string()
    }
}

impl std::fmt::Display for Address {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}", self.host, self.port)
    }
}

/// An address that is not `HOST:PORT`.
#[derive(Debug, Error, PartialEq, Eq)]
pub enum AddressError {
    #[error("{text:?}: the port {port:?} is not a number from 1 to 65535")]
    Port { text: String, port: String },
    #[error("{0:?}: expected HOST, HOST:PORT or :PORT, e.g. 127.0.0.1:1667")]
    Shape(String),
}

/// What went wrong talking to a publisher.
#[derive(Debug, Error)]
pub enum ClientError {
    #[error("no Groot2 publisher answers at {address}: {reason}")]
    Connect { address: Address, reason: String },
    #[error(
        "{address} accepts connections but not ZeroMQ's greeting ({reason}); Groot2's publisher listens on the port given to it (1667 unless told otherwise)"
    )]
    NotZeroMq { address: Address, reason: String },
    #[error("{address} did not answer a {request} request within {millis} ms")]
    Timeout {
        address: Address,
        request: &'static str,
        millis: u128,
    },
    #[error("the connection to {address} was lost: {reason}")]
    Lost { address: Address, reason: String },
    #[error("{address}: {source}")]
    Protocol {
        address: Address,
        source: ProtocolError,
    },
    #[error("{address}: {source}")]
    Tree { address: Address, source: TreeError },
    #[error("{address}: the reply to a {request} request has no payload")]
    Empty {
        address: Address,
        request: &'static str,
    },
}

/// A connected publisher.
pub struct Publisher {
    address: Address,
    socket: ReqSocket,
    next_id: u32,
    timeout: Duration,
}

/// The publisher's tree id: a new one means a new tree (the robot restarted).
pub type TreeId = [u8; 16];

impl Publisher {
    /// Connects, giving up after `timeout` (a port no one listens on, a host not there).
    pub async fn connect(address: &Address, timeout: Duration) -> Result<Publisher, ClientError> {
        // A plain TCP connection first: ZeroMQ retries a refused connection until its
        // time is up and then says only that, where the socket's own error (refused,
        // unreachable, no such host) tells the person what to fix.
        let probe =
            tokio::net::TcpStream::connect((address.host.trim_matches(['[', ']']), address.port));
        match tokio::time::timeout(timeout, probe).await {
            Ok(Ok(_)) => {}
            Ok(Err(e)) => {
                return Err(ClientError::Connect {
                    address: address.clone(),
                    reason: e.to_string(),
                });
            }
            Err(_) => {
                return Err(ClientError::Connect {
                    address: address.clone(),
                    reason: format!("no answer within {} ms", timeout.as_millis()),
                });
            }
        }
        let mut options = SocketOptions::default();
        options.connect_timeout(timeout);
        let mut socket = ReqSocket::with_options(options);
        socket
            .connect(&address.endpoint())
            .await
            .map_err(|e| ClientError::NotZeroMq {
                address: address.clone(),
                reason: e.to_string(),
            })?;
        Ok(Publisher {
            address: address.clone(),
            socket,
            next_id: rand_id(),
            timeout,
        })
    }

    pub fn address(&self) -> &Address {
        &self.address
    }

    async fn ask(
        &mut self,
        kind: RequestKind,
        body: Option<&[u8]>,
    ) -> Result<(TreeId, Option<Vec<u8>>), ClientError> {
        self.next_id = self.next_id.wrapping_add(1);
        let mut request = Request::new(kind, self.next_id);
        if let Some(body) = body {
            request = request.with_body(body);
        }
        let mut frames = request.frames().into_iter().map(bytes::Bytes::from);
        let mut message = ZmqMessage::from(frames.next().unwrap_or_default());
        for frame in frames {
            message.push_back(frame);
        }
        let lost = |e: zeromq::ZmqError| ClientError::Lost {
            address: self.address.clone(),
            reason: e.to_string(),
        };
        let timeout = ClientError::Timeout {
            address: self.address.clone(),
            request: kind.name(),
            millis: self.timeout.as_millis(),
        };
        let exchange = async {
            self.socket.send(message).await?;
            self.socket.recv().await
        };
        let reply = match tokio::time::timeout(self.timeout, exchange).await {
            Err(_) => return Err(timeout),
            Ok(Err(e)) => return Err(lost(e)),
            Ok(Ok(reply)) => reply,
        };
        let frames = reply.into_vec();
        let slices: Vec<&[u8]> = frames.iter().map(|f| f.as_ref()).collect();
        let read = request
            .read_reply(&slices)
            .map_err(|source| ClientError::Protocol {
                address: self.address.clone(),
                source,
            })?;
        Ok((read.tree_id, read.payload.map(<[u8]>::to_vec)))
    }

    async fn ask_payload(
        &mut self,
        kind: RequestKind,
        body: Option<&[u8]>,
    ) -> Result<(TreeId, Vec<u8>), ClientError> {
        let (id, payload) = self.ask(kind, body).await?;
        let payload = payload.ok_or_else(|| ClientError::Empty {
            address: self.address.clone(),
            request: kind.name(),
        })?;
        Ok((id, payload))
    }

    /// The tree the publisher runs.
    pub async fn tree(&mut self) -> Result<(TreeId, WatchedTree), ClientError> {
        let (id, xml) = self.ask_payload(RequestKind::FullTree, None).await?;
        let tree = WatchedTree::parse(&xml).map_err(|source| ClientError::Tree {
            address: self.address.clone(),
            source,
        })?;
        Ok((id, tree))
    }

    /// Every node's status now.
    pub async fn statuses(&mut self) -> Result<(TreeId, Vec<(u16, NodeStatus)>), ClientError> {
        let (id, payload) = self.ask_payload(RequestKind::Status, None).await?;
        let statuses = protocol::read_statuses(&payload).map_err(|source| self.protocol(source))?;
        Ok((id, statuses))
    }

    /// Asks the publisher to keep every status change from now on; the publisher's clock
    /// at that moment, when it says (BT.CPP 4 answers with microseconds since the Unix
    /// epoch, the clock its changes are timed by).
    pub async fn start_recording(&mut self) -> Result<(TreeId, Option<SystemTime>), ClientError> {
        let (id, payload) = self
            .ask(RequestKind::ToggleRecording, Some(b"start"))
            .await?;
        let started = payload
            .and_then(|p| String::from_utf8(p).ok())
            .and_then(|t| t.trim().parse::<u64>().ok())
            .map(|micros| UNIX_EPOCH + Duration::from_micros(micros));
        Ok((id, started))
    }

    /// A request that changes the publisher's breakpoints (its reply carries nothing).
    pub async fn command(
        &mut self,
        kind: RequestKind,
        body: Option<&[u8]>,
    ) -> Result<(), ClientError> {
        self.ask(kind, body).await.map(|_| ())
    }

    /// The publisher's notifications: it says on its second port (its request port + 1)
    /// when a node stops at a breakpoint.
    pub async fn notifications(&self) -> Result<Notifications, ClientError> {
        let address = Address {
            host: self.address.host.clone(),
            port: self.address.port.wrapping_add(1),
        };
        let mut options = SocketOptions::default();
        options.connect_timeout(self.timeout);
        let mut socket = SubSocket::with_options(options);
        let failed = |e: zeromq::ZmqError| ClientError::Connect {
            address: address.clone(),
            reason: format!("the publisher's notification port: {e}"),
        };
        socket.connect(&address.endpoint()).await.map_err(failed)?;
        socket.subscribe("").await.map_err(failed)?;
        Ok(Notifications { address, socket })
    }

    /// The blackboards named, with their entries (a name the publisher does not know is
    /// left out).
    pub async fn blackboards(
        &mut self,
        names: &[&str],
    ) -> Result<Vec<protocol::Blackboard>, ClientError> {
        let body = names.join(";");
        let (_, payload) = self
            .ask_payload(RequestKind::Blackboard, Some(body.as_bytes()))
            .await?;
        protocol::read_blackboards(&payload).map_err(|source| self.protocol(source))
    }

    /// The status changes since the last call (or since recording started).
    pub async fn transitions(&mut self) -> Result<(TreeId, Vec<Transition>), ClientError> {
        let (id, payload) = self.ask_payload(RequestKind::Transitions, None).await?;
        let transitions =
            protocol::read_transitions(&payload).map_err(|source| self.protocol(source))?;
        Ok((id, transitions))
    }

    fn protocol(&self, source: ProtocolError) -> ClientError {
        ClientError::Protocol {
            address: self.address.clone(),
            source,
        }
    }
}

/// The publisher's notifications of nodes stopped at a breakpoint.
pub struct Notifications {
    address: Address,
    socket: SubSocket,
}

impl Notifications {
    /// The next node stopped at a breakpoint.
    pub async fn stopped(&mut self) -> Result<u16, ClientError> {
        let message = self.socket.recv().await.map_err(|e| ClientError::Lost {
            address: self.address.clone(),
            reason: e.to_string(),
        })?;
        let frames = message.into_vec();
        let slices: Vec<&[u8]> = frames.iter().map(|f| f.as_ref()).collect();
        protocol::read_breakpoint_reached(&slices).map_err(|source| ClientError::Protocol {
            address: self.address.clone(),
            source,
        })
    }
}

/// A request id to start from; the publisher only echoes it, so the clock will do.
fn rand_id() -> u32 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(1, |d| d.subsec_nanos())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_address_is_a_host_and_a_port_defaulting_to_groot2s() {
        let a = |t: &str| Address::parse(t);
        assert_eq!(a("robot.local").unwrap().to_string(), "robot.local:1667");
        assert_eq!(a("10.0.0.2:1777").unwrap().to_string(), "10.0.0.2:1777");
        assert_eq!(a(":1700").unwrap().to_string(), "127.0.0.1:1700");
        assert_eq!(a("[::1]:1700").unwrap().host, "[::1]");
        assert!(
            a("host:0")
                .unwrap_err()
                .to_string()
                .contains("from 1 to 65535")
        );
        assert!(a("host:http").unwrap_err().to_string().contains("\"http\""));
        assert!(a("tcp://x").is_err());
    }
}
