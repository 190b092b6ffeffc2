//! Capture without a sound card: the collector (sample gathering and level reports), the
//! mapping of device errors to what a person can do, and — on a machine without any
//! input device, like the CI machine — that starting a recording fails with a clear error
//! instead of hanging or panicking.

use std::sync::mpsc;

use super::*;

#[test]
fn the_collector_keeps_every_sample_and_reports_a_level_per_50_ms() {
    let (tx, rx) = mpsc::channel();
    let mut c = Collector::new(16_000, 2, Box::new(move |l| tx.send(l).unwrap()));
    // 0.125 s of stereo at half scale, in uneven chunks as a driver delivers them.
    let data: Vec<f32> = (0..4_000)
        .map(|i| if i % 2 == 0 { 0.5 } else { -0.5 })
        .collect();
    for chunk in data.chunks(333) {
        c.push(chunk.iter().copied());
    }
    assert_eq!(c.samples, data);
    let levels: Vec<Level> = rx.try_iter().collect();
    assert_eq!(levels.len(), 2, "two full 50 ms windows of 1600 samples");
    assert!(levels.iter().all(|l| (l.peak_dbfs + 6.02).abs() < 0.01));
}

#[test]
fn device_errors_say_what_to_do() {
    let busy = classify(&cpal::ErrorKind::DeviceBusy.into(), "hw:0");
    assert!(matches!(busy, VoiceError::DeviceBusy { .. }));
    assert!(busy.to_string().contains("busy") && busy.to_string().contains("hw:0"));
    let gone = classify(&cpal::ErrorKind::DeviceNotAvailable.into(), "USB mic");
    assert!(matches!(gone, VoiceError::NoInputDevice { .. }));
    assert!(gone.to_string().contains("--audio"), "{gone}");
    let denied = classify(&cpal::ErrorKind::PermissionDenied.into(), "hw:0");
    assert!(denied.to_string().contains("audio` group"), "{denied}");
    let format = classify(&cpal::ErrorKind::UnsupportedConfig.into(), "hw:0");
    assert!(matches!(format, VoiceError::UnsupportedConfig { .. }));
}

/// Whether this machine has no sound card at all (Linux).
fn no_sound_card() -> bool {
    std::fs::read_to_string("/proc/asound/cards")
        .map_or(true, |cards| cards.contains("no soundcards"))
}

#[test]
fn without_a_sound_card_starting_a_recording_is_a_clear_error() {
    if !no_sound_card() {
        // Nothing to check where a sound card is: under CI (whose machines have none) that
        // is a failure, not a quiet pass.
        assert!(
            !std::env::var("CI")
                .is_ok_and(|v| !(v.is_empty() || v == "0" || v.eq_ignore_ascii_case("false"))),
            "this machine has a sound card, so a recording without one cannot be checked, and CI is set"
        );
        eprintln!(
            "\n!!!!! SKIPPED: this machine has a sound card; without_a_sound_card_starting_a_recording_is_a_clear_error checks nothing here (under CI it fails) !!!!!\n"
        );
        return;
    }
    let err = Recorder::start(|_| {}).err().unwrap();
    assert!(
        matches!(
            err,
            VoiceError::NoInputDevice { .. }
                | VoiceError::Capture { .. }
                | VoiceError::UnsupportedConfig { .. }
        ),
        "{err:?}"
    );
    eprintln!("{err}");
}
