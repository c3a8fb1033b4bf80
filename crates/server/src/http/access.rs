//! The access-token gate in front of every viewer route, when gantry runs with
//! `--token`, and the same-origin check on the WebSocket.
//!
//! A request passes with the token in any of three places:
//! * `?token=TOKEN` in the URL: how a person opens the page (`gantry run` prints that
//!   URL). The response then sets a cookie, so the page's assets, its WebSocket and the
//!   CSV links carry the token without it appearing in them;
//! * the cookie `gantry_token_PORT` (HttpOnly, so the page's scripts cannot read it;
//!   SameSite=Strict, so other sites' pages cannot make the browser send it). The port
//!   is in the name because cookies ignore ports: two gantries on one host would
//!   otherwise overwrite each other's;
//! * `Authorization: Bearer TOKEN`: for scripts and `curl`.
//!
//! Anything else gets 401 with a one-line explanation. There is no login form and no
//! session store: the token is the credential, compared in constant time each request.

use std::sync::Arc;

use axum::extract::{Request, State};
use axum::http::{HeaderMap, HeaderValue, StatusCode, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};

use crate::auth::AccessToken;

/// What the gate checks requests against.
#[derive(Clone)]
pub(super) struct Gate {
    token: AccessToken,
    /// `gantry_token_PORT`.
    cookie: Arc<str>,
}

impl Gate {
    /// A gate for the viewer listening on `port`.
    pub(super) fn new(token: AccessToken, port: u16) -> Self {
        Self {
            token,
            cookie: format!("gantry_token_{port}").into(),
        }
    }
}

/// The middleware: lets a request through when it carries the token, else answers 401.
pub(super) async fn check(State(gate): State<Gate>, req: Request, next: Next) -> Response {
    let matches = |t: &str| gate.token.matches(t.as_bytes());
    let in_query = query_token(req.uri().query()).is_some_and(matches);
    let allowed = in_query
        || cookie_tokens(req.headers(), &gate.cookie).any(matches)
        || bearer_token(req.headers()).is_some_and(matches);
    if !allowed {
        tracing::info!("viewer: refusing {} without the access token", req.uri().path());
        return (
            StatusCode::UNAUTHORIZED,
            [
                (header::WWW_AUTHENTICATE, "Bearer realm=\"gantry\""),
                (header::CONTENT_TYPE, "text/plain; charset=utf-8"),
            ],
            "this gantry requires an access token: open the address it printed at start-up \
             (http://HOST:PORT/?token=...), or send the header 'Authorization: Bearer TOKEN'\n",
        )
            .into_response();
    }
    let mut response = next.run(req).await;
    let headers = response.headers_mut();
    // The page's URL may hold the token; keep it out of any Referer header.
    headers.insert(header::REFERRER_POLICY, HeaderValue::from_static("no-referrer"));
    if in_query {
        // The token is URL-safe by construction (see AccessToken::new), so it needs no
        // quoting here. No `Secure`: the viewer speaks plain HTTP.
        let cookie = format!(
            "{}={}; HttpOnly; SameSite=Strict; Path=/",
            gate.cookie,
            gate.token.reveal()
        );
        if let Ok(v) = HeaderValue::from_str(&cookie) {
            headers.append(header::SET_COOKIE, v);
        }
    }
    response
}

/// The value of `token=` in a query string. Tokens use URL-safe characters only, so
/// the value is compared as it is, without percent-decoding.
fn query_token(query: Option<&str>) -> Option<&str> {
    query?.split('&').find_map(|pair| pair.strip_prefix("token="))
}

/// Every value of the cookie `name` (a browser may send a name twice, with different
/// paths).
fn cookie_tokens<'a>(headers: &'a HeaderMap, name: &'a str) -> impl Iterator<Item = &'a str> + 'a {
    headers
        .get_all(header::COOKIE)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(|v| v.split(';'))
        .filter_map(move |pair| {
            let (k, v) = pair.trim().split_once('=')?;
            (k == name).then_some(v)
        })
}

/// The token of an `Authorization: Bearer TOKEN` header.
fn bearer_token(headers: &HeaderMap) -> Option<&str> {
    let v = headers.get(header::AUTHORIZATION)?.to_str().ok()?;
    let (scheme, token) = v.trim().split_once(' ')?;
    scheme.eq_ignore_ascii_case("bearer").then(|| token.trim())
}

/// Whether a WebSocket upgrade comes from a page of this very server, or from a
/// program (no `Origin` header). Browsers send `Origin` with every WebSocket handshake
/// and, unlike `fetch`, WebSocket has no CORS check, so without this any web page the
/// user visits could open `ws://127.0.0.1:8080/ws` and drive the simulation.
pub(super) fn same_origin(headers: &HeaderMap) -> bool {
    let Some(origin) = headers.get(header::ORIGIN) else {
        return true;
    };
    let host = headers.get(header::HOST).and_then(|h| h.to_str().ok());
    let origin_host = origin
        .to_str()
        .ok()
        .and_then(|o| o.split_once("://"))
        .map(|(_, rest)| rest.trim_end_matches('/'));
    matches!((origin_host, host), (Some(o), Some(h)) if o.eq_ignore_ascii_case(h))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn headers(pairs: &[(header::HeaderName, &str)]) -> HeaderMap {
        let mut h = HeaderMap::new();
        for (k, v) in pairs {
            h.append(k.clone(), HeaderValue::from_str(v).expect("header value"));
        }
        h
    }

    #[test]
    fn tokens_are_found_in_query_cookie_and_header() {
        assert_eq!(query_token(Some("token=abc")), Some("abc"));
        assert_eq!(query_token(Some("x=1&token=abc&y=2")), Some("abc"));
        assert_eq!(query_token(Some("mytoken=abc")), None);
        assert_eq!(query_token(None), None);
        let h = headers(&[
            (header::COOKIE, "a=1; gantry_token_8080=one"),
            (header::COOKIE, "gantry_token_8080=two"),
            (header::AUTHORIZATION, "Bearer  xyz "),
        ]);
        assert_eq!(
            cookie_tokens(&h, "gantry_token_8080").collect::<Vec<_>>(),
            ["one", "two"]
        );
        assert_eq!(cookie_tokens(&h, "gantry_token_8081").count(), 0);
        assert_eq!(bearer_token(&h), Some("xyz"));
        assert_eq!(bearer_token(&headers(&[(header::AUTHORIZATION, "Basic xyz")])), None);
    }

    #[test]
    fn websocket_origins() {
        let host = (header::HOST, "127.0.0.1:8080");
        assert!(
            same_origin(&headers(std::slice::from_ref(&host))),
            "programs send no Origin"
        );
        assert!(same_origin(&headers(&[
            host.clone(),
            (header::ORIGIN, "http://127.0.0.1:8080")
        ])));
        assert!(!same_origin(&headers(&[
            host.clone(),
            (header::ORIGIN, "http://evil.example")
        ])));
        assert!(!same_origin(&headers(&[host.clone(), (header::ORIGIN, "null")])));
        assert!(
            !same_origin(&headers(&[(header::ORIGIN, "http://127.0.0.1:8080")])),
            "no Host"
        );
    }
}
