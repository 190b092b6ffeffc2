use super::*;

#[test]
fn later_layers_win() {
    let file: crate::config_file::FileConfig = toml::from_str(
        "[llm]\nmodel = \"a\"\nbase_url = \"http://f/v1\"\nstructured = true\n[prices.a]\nprompt_per_mtok = 1.0\ncompletion_per_mtok = 2.0\n",
    )
    .unwrap();
    let env = Layer::from_env(&|k| (k == "BETR_MODEL").then(|| "b".to_string())).unwrap();
    let flags = Layer {
        base_url: Some("http://flag/v1".into()),
        ..Layer::default()
    };
    let s = Settings::resolve(
        Some((Path::new("betr.toml"), file.llm, file.prices)),
        env,
        flags,
    )
    .unwrap();
    assert_eq!(s.model.as_deref(), Some("b"));
    assert_eq!(s.base_url, "http://flag/v1");
    assert!(s.structured);
    assert!(s.prices.price("a").is_some());
    assert_eq!(s.api_key_env.as_deref(), Some("OPENAI_API_KEY"));
}

#[test]
fn the_documented_example_resolves() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("betr.example.toml");
    let file = crate::config_file::FileConfig::read(&path).unwrap();
    assert_eq!(file.llm.backend, Some(Backend::Openai));
    assert!(file.prices.price("gpt-4o-2024-08-06").is_some());
    let s = Settings::resolve(
        Some((&path, file.llm, file.prices)),
        Layer::default(),
        Layer::default(),
    )
    .unwrap();
    assert_eq!(s.retry.max_retries, 3);
}

#[test]
fn keys_and_bad_values_are_refused() {
    assert!(Layer::from_env(&|k| (k == "BETR_BACKEND").then(|| "gpt".into())).is_err());
    let local = Settings::resolve(
        None,
        Layer::default(),
        Layer {
            backend: Some(Backend::Local),
            model_path: Some("/nonexistent/model.gguf".into()),
            ..Layer::default()
        },
    )
    .unwrap();
    let e = local.build(Ledger::default(), &|_| None).err().unwrap();
    assert!(
        e.to_string()
            .contains("/nonexistent/model.gguf does not exist"),
        "{e}"
    );
    let unknown = Settings::resolve(
        None,
        Layer::default(),
        Layer {
            model: Some("gpt-9".into()),
            ..Layer::default()
        },
    )
    .unwrap();
    assert_eq!(unknown.backend, Backend::Local, "offline by default");
    assert!(
        unknown
            .local_model()
            .unwrap_err()
            .to_string()
            .contains("unknown local model \"gpt-9\"")
    );
}

#[test]
fn every_number_is_checked_against_its_range() {
    let refused = |layer: Layer, said: &str| {
        let e = Settings::resolve(None, Layer::default(), layer)
            .unwrap_err()
            .to_string();
        assert!(e.contains(said), "{e}");
    };
    let d = Layer::default;
    for t in [1e20, 0.0, -5.0, f64::NAN, 3601.0] {
        let timeout = Layer {
            timeout_secs: Some(t),
            ..d()
        };
        refused(timeout, "timeout_secs = ");
        let connect = Layer {
            connect_timeout_secs: Some(t),
            ..d()
        };
        refused(connect, "connect_timeout_secs = ");
    }
    let out_of_range = [
        (
            Layer {
                temperature: Some(f32::INFINITY),
                ..d()
            },
            "temperature = inf is out of range",
        ),
        (
            Layer {
                max_tokens: Some(0),
                ..d()
            },
            "max_tokens = 0",
        ),
        (
            Layer {
                max_retries: Some(4_000_000_000),
                ..d()
            },
            "max_retries",
        ),
        (
            Layer {
                max_backoff_ms: Some(u64::MAX),
                ..d()
            },
            "max_backoff_ms",
        ),
        (
            Layer {
                threads: Some(0),
                ..d()
            },
            "threads = 0",
        ),
        (
            Layer {
                context: Some(u32::MAX),
                ..d()
            },
            "context = ",
        ),
        (
            Layer {
                max_reply_bytes: Some(1 << 40),
                ..d()
            },
            "max_reply_bytes = ",
        ),
    ];
    for (layer, said) in out_of_range {
        refused(layer, said);
    }
    let s = Settings::resolve(None, Layer::default(), Layer::default()).unwrap();
    assert_eq!(s.max_reply_bytes, 256 * 1024);
    assert_eq!(s.timeout, Duration::from_secs(60));
}
