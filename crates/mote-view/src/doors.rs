//! Who may come in: the checks every request passes before any handler.
//!
//! A page on 127.0.0.1 is reachable from every other page open in the
//! user's browser, so three doors are kept (as Jupyter keeps them):
//!
//! - **Host**: the server answers only requests addressed to itself, by
//!   `localhost`, a loopback address or the address it was bound to (any IP
//!   literal where it was bound to all interfaces), with its port. A site
//!   that points its own name at 127.0.0.1 (DNS rebinding) is turned away:
//!   its requests carry its name.
//! - **Origin**: a request a page sends carries that page's origin; only
//!   the viewer's own (`http://` + an accepted host) is let in, so another
//!   site cannot open the live socket or read what the page reads.
//! - **Token**: the live run's socket (`/api/live`, which can pause and
//!   change the run) needs the run's token, a random 128-bit number that
//!   `mote view` prints in the URL it gives; the page passes it on.

use std::net::{IpAddr, SocketAddr};

use axum::extract::{Request, State};
use axum::http::{header, StatusCode};
use axum::middleware::Next;
use axum::response::Response;

/// The host names and origins a server on one address accepts.
#[derive(Debug, Clone)]
pub struct Doors {
    /// The address the server listens on.
    bound: SocketAddr,
}

impl Doors {
    /// The doors of a server listening on `bound`.
    pub fn new(bound: SocketAddr) -> Doors {
        Doors { bound }
    }

    /// Whether a `Host` header value names this server.
    pub fn host_ok(&self, host: &str) -> bool {
        let Some((name, port)) = split_host(host) else {
            return false;
        };
        if port.unwrap_or(80) != self.bound.port() {
            return false;
        }
        if name.eq_ignore_ascii_case("localhost") {
            return true;
        }
        let Ok(ip) = name.parse::<IpAddr>() else {
            // Any other name may be an attacker's, pointed at us.
            return false;
        };
        ip.is_loopback() || ip == self.bound.ip() || self.bound.ip().is_unspecified()
    }

    /// Whether an `Origin` header value is the viewer's own page.
    pub fn origin_ok(&self, origin: &str) -> bool {
        origin
            .strip_prefix("http://")
            .is_some_and(|host| self.host_ok(host))
    }
}

/// `name[:port]` or `[v6][:port]` into the name (without brackets) and the
/// port; `None` if it is neither.
fn split_host(host: &str) -> Option<(&str, Option<u16>)> {
    let (name, rest) = if let Some(v6) = host.strip_prefix('[') {
        let (name, rest) = v6.split_once(']')?;
        (name, rest)
    } else {
        match host.split_once(':') {
            Some((name, _)) => (name, &host[name.len()..]),
            None => (host, ""),
        }
    };
    let port = match rest {
        "" => None,
        p => Some(p.strip_prefix(':')?.parse().ok()?),
    };
    (!name.is_empty()).then_some((name, port))
}

/// The middleware: a foreign `Host` or `Origin` is answered 403 before any
/// handler runs.
pub async fn guard(State(doors): State<Doors>, request: Request, next: Next) -> Response {
    let headers = request.headers();
    let host = headers.get(header::HOST).and_then(|v| v.to_str().ok());
    if !host.is_some_and(|h| doors.host_ok(h)) {
        return super::text(
            StatusCode::FORBIDDEN,
            format!(
                "this server answers only requests to its own address ({}), not to {}",
                doors.bound,
                host.unwrap_or("no Host")
            ),
        );
    }
    if let Some(origin) = headers.get(header::ORIGIN) {
        if !origin.to_str().is_ok_and(|o| doors.origin_ok(o)) {
            return super::text(
                StatusCode::FORBIDDEN,
                "requests from other pages' origins are refused".into(),
            );
        }
    }
    next.run(request).await
}

/// A new live run's token: 128 random bits as 32 hexadecimal digits.
pub fn new_token() -> String {
    format!("{:032x}", rand::random::<u128>())
}

/// Whether `given` is `token`, compared in time independent of where they
/// differ.
pub fn token_matches(given: &str, token: &str) -> bool {
    given.len() == token.len()
        && given
            .bytes()
            .zip(token.bytes())
            .fold(0u8, |d, (a, b)| d | (a ^ b))
            == 0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_servers_own_names_are_hosts() {
        let doors = Doors::new("127.0.0.1:8123".parse().unwrap());
        for ok in [
            "127.0.0.1:8123",
            "localhost:8123",
            "LOCALHOST:8123",
            "[::1]:8123",
        ] {
            assert!(doors.host_ok(ok), "{ok}");
        }
        for bad in [
            "evil.example:8123",
            "127.0.0.1.nip.io:8123",
            "127.0.0.1:8124",
            "127.0.0.1",
            "192.168.1.5:8123",
            "",
            "[::1",
            "localhost:",
            "localhost:x",
        ] {
            assert!(!doors.host_ok(bad), "{bad}");
        }
        let all = Doors::new("0.0.0.0:80".parse().unwrap());
        assert!(all.host_ok("192.168.1.5"));
        assert!(all.host_ok("192.168.1.5:80"));
        assert!(!all.host_ok("attacker.example"));
        assert!(doors.origin_ok("http://localhost:8123"));
        for bad in ["null", "https://localhost:8123", "http://evil.example:8123"] {
            assert!(!doors.origin_ok(bad), "{bad}");
        }
    }

    #[test]
    fn tokens_are_new_and_compared_whole() {
        let (a, b) = (new_token(), new_token());
        assert_ne!(a, b);
        assert_eq!(a.len(), 32);
        assert!(token_matches(&a, &a.clone()));
        assert!(!token_matches(&a, &b));
        assert!(!token_matches(&a[..31], &a));
    }
}
