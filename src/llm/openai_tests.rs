use super::*;
use crate::llm::Message;

fn client(structured: bool) -> OpenAiClient {
    client_with_key(structured, "sk-secret")
}

fn client_with_key(structured: bool, key: &str) -> OpenAiClient {
    OpenAiClient::new(OpenAiSettings {
        base_url: "http://127.0.0.1:9/v1/".into(),
        model: "m".into(),
        api_key_env: Some("K".into()),
        api_key: Some(ApiKey::new(key)),
        auth_header: AuthHeader::Bearer,
        timeout: Duration::from_secs(1),
        connect_timeout: Duration::from_secs(1),
        retry: RetryPolicy::default(),
        structured,
        max_tokens_field: "max_tokens".into(),
        max_reply_bytes: 256 * 1024,
    })
    .unwrap()
}

#[test]
fn body_follows_the_wire_format() {
    let mut req = ChatRequest::new(vec![Message::user("hi")]);
    req.constraint = Some(OutputConstraint::JsonSchema {
        name: "x".into(),
        schema: json!({"type": "object"}),
    });
    let c = client(false);
    assert_eq!(c.url, "http://127.0.0.1:9/v1/chat/completions");
    let b = c.body(&req);
    assert_eq!(b["messages"][0]["role"], "user");
    assert_eq!(b["max_tokens"], 800);
    assert!(b.get("response_format").is_none());
    let b = client(true).body(&req);
    assert_eq!(b["response_format"]["type"], "json_schema");
}

#[test]
fn key_never_shows() {
    let c = client(false);
    assert!(!format!("{:?}", c.settings).contains("sk-secret"));
    assert_eq!(
        c.detail(r#"{"error":{"message":"bad key sk-secret"}}"#),
        "bad key <redacted>"
    );
}

#[test]
fn replies_are_checked() {
    let c = client(false);
    let d = Duration::ZERO;
    assert!(matches!(
        c.parse_reply("{", d),
        Err(LlmError::MalformedReply { .. })
    ));
    assert!(matches!(
        c.parse_reply(r#"{"choices":[]}"#, d),
        Err(LlmError::EmptyChoices { .. })
    ));
    let r = c
        .parse_reply(
            r#"{"choices":[{"message":{"content":"Goal: A"}}],"usage":{"prompt_tokens":3,"completion_tokens":2}}"#,
            d,
        )
        .unwrap();
    assert_eq!(
        (r.text.as_str(), r.usage.prompt_tokens, r.model.as_str()),
        ("Goal: A", 3, "m")
    );
}

/// What the model wrote is read as written, whatever the key: a placeholder key such as
/// `test` takes no word out of a reply (the key stays out of the messages betr writes).
#[test]
fn replies_are_read_as_the_model_wrote_them_whatever_the_key() {
    let reply = r#"{"choices":[{"message":{"content":"Goal: \"test tube\" in rack & x"}}]}"#;
    for key in ["test", "x", "sk-secret"] {
        let c = client_with_key(false, key);
        let r = c.parse_reply(reply, Duration::ZERO).unwrap();
        assert_eq!(r.text, r#"Goal: "test tube" in rack & x"#, "key {key:?}");
    }
    assert_eq!(
        client_with_key(false, "test").detail(r#"{"error":{"message":"bad key test"}}"#),
        "bad key <redacted>"
    );
}
