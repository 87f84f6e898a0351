//! Checkpoint directories: a staged checkpoint replaces the old one whole, and the staging and
//! previous siblings are gone afterwards; a model with its optimizer and the run state round-trip.

use emg_learning::checkpoint::{publish, stage};

#[test]
fn a_published_checkpoint_replaces_the_previous_one() {
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    let dir = root.join("run");
    for (round, name) in [(1, "first.txt"), (2, "second.txt")] {
        let staging = stage(&dir).unwrap();
        assert!(staging.is_dir() && std::fs::read_dir(&staging).unwrap().next().is_none());
        std::fs::write(staging.join(name), format!("{round}")).unwrap();
        publish(&dir).unwrap();
        assert_eq!(
            std::fs::read_to_string(dir.join(name)).unwrap(),
            format!("{round}")
        );
        assert!(!staging.exists());
        assert!(!root.join("run.previous").exists());
    }
    assert!(
        !dir.join("first.txt").exists(),
        "the old checkpoint is replaced, not merged"
    );
}

#[test]
fn run_state_round_trips_and_a_missing_state_names_its_file() {
    use emg_learning::checkpoint::{read_state, write_state};
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    let dir = root.join("run");
    let staging = stage(&dir).unwrap();
    write_state(&staging, &(7_u64, vec![0.25_f64, -1.5])).unwrap();
    publish(&dir).unwrap();
    let state: (u64, Vec<f64>) = read_state(&dir).unwrap();
    assert_eq!(state, (7, vec![0.25, -1.5]));
    let error = read_state::<u64>(&root.join("missing")).unwrap_err();
    assert!(error.to_string().contains("state.json"), "{error}");
}

#[test]
fn a_model_and_its_optimizer_round_trip_and_a_missing_file_is_named() {
    use burn::nn::{Linear, LinearConfig};
    use emg_learning::Backend;
    use emg_learning::checkpoint::{read_training, write_training};

    let device = Backend::Flex.device();
    let saved: Linear = LinearConfig::new(3, 2).init(&device);
    let fresh = || {
        let model: Linear = LinearConfig::new(3, 2).init(&device);
        (model, burn::optim::AdamConfig::new().init())
    };
    let (other, optimizer) = fresh();
    let weights = |model: &Linear| model.weight.val().into_data().try_to_vec::<f32>().unwrap();
    assert_ne!(
        weights(&saved),
        weights(&other),
        "two initialisations differ"
    );

    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    let staging = stage(&dir).unwrap();
    write_training(&staging, &saved, &optimizer).unwrap();
    publish(&dir).unwrap();
    let (loaded, _) = read_training(&dir, other, optimizer).unwrap();
    assert_eq!(weights(&loaded), weights(&saved));

    let (model, optimizer) = fresh();
    let Err(error) = read_training(&tmp.path().join("missing"), model, optimizer) else {
        panic!("a missing checkpoint must not load");
    };
    assert!(error.to_string().contains("model.bpk"), "{error}");
}
