//! Exported weights: the plain-Rust forward agrees with Burn on both backends, files round-trip,
//! and broken files give clear errors.

use burn::tensor::{Tensor, TensorData};
use emg_policy::{
    ACTION_DIM, Backend, ContainerError, NetworkConfig, OBSERVATION_DIM, PlainPolicy,
    PolicyWeights, PpoConfig, Trainer, WeightsError,
};

fn trained_weights(backend: Backend) -> PolicyWeights {
    let ppo = PpoConfig {
        seed: 3,
        log_std_bias: -0.5,
        ..PpoConfig::default()
    };
    Trainer::new(
        NetworkConfig {
            hidden: vec![24, 16],
            ..NetworkConfig::default()
        },
        ppo,
        backend,
    )
    .expect("valid configuration")
    .weights()
}

fn observations() -> Vec<[f32; OBSERVATION_DIM]> {
    (0..5)
        .map(|k| std::array::from_fn(|i| ((i * 7 + k * 13) % 17) as f32 / 8.0 - 1.0))
        .collect()
}

fn plain_matches_burn(backend: Backend) {
    let weights = trained_weights(backend);
    let device = backend.device();
    let model = weights.to_model(&device);
    let plain = PlainPolicy::new(&weights);
    let mut scratch = plain.scratch();
    let rows = observations();
    let flat: Vec<f32> = rows.iter().flatten().copied().collect();
    let input = Tensor::<2>::from_data(
        TensorData::new(flat, [rows.len(), OBSERVATION_DIM]),
        &device,
    );
    let range = (-5.0, 0.0);
    let output = model.policy(input.clone(), range);
    let means = output.mean.into_data().try_to_vec::<f32>().expect("f32");
    let log_stds = output.log_std.into_data().try_to_vec::<f32>().expect("f32");
    let values = model
        .value(input)
        .into_data()
        .try_to_vec::<f32>()
        .expect("f32");
    for (r, observation) in rows.iter().enumerate() {
        let actor = plain.actor(observation, &mut scratch);
        for k in 0..ACTION_DIM {
            let (mean, log_std) = (means[r * ACTION_DIM + k], log_stds[r * ACTION_DIM + k]);
            assert!(
                (actor.mean[k] - mean).abs() < 1e-5,
                "row {r} mean {k}: {} vs {mean}",
                actor.mean[k]
            );
            assert!(
                (actor.log_std[k] - log_std).abs() < 1e-5,
                "row {r} log-std {k}"
            );
        }
        let value = plain.value(observation, &mut scratch);
        assert!(
            (value - values[r]).abs() < 1e-5,
            "row {r} value: {value} vs {}",
            values[r]
        );
    }
}

#[test]
fn plain_forward_agrees_with_burn_on_flex() {
    plain_matches_burn(Backend::Flex);
}

#[test]
fn plain_forward_agrees_with_burn_on_ndarray() {
    plain_matches_burn(Backend::Ndarray);
}

#[test]
fn weights_round_trip_through_a_file() {
    let weights = trained_weights(Backend::Flex);
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("policy.weights");
    weights.write(&path).unwrap();
    assert_eq!(PolicyWeights::read(&path).unwrap(), weights);
}

#[test]
fn a_truncated_file_is_refused_with_a_clear_error() {
    let bytes = trained_weights(Backend::Flex).to_bytes();
    let error = PolicyWeights::from_bytes(&bytes[..bytes.len() - 6]).unwrap_err();
    assert!(
        matches!(
            error,
            WeightsError::Format(ContainerError::Truncated { part: "values", .. })
        ),
        "{error}"
    );
    assert!(
        error
            .to_string()
            .contains("not a valid policy weights file")
    );
    let cause = std::error::Error::source(&error)
        .expect("the container error")
        .to_string();
    assert!(cause.contains("truncated"), "{cause}");
    let error = PolicyWeights::from_bytes(&bytes[..10]).unwrap_err();
    assert!(
        matches!(
            error,
            WeightsError::Format(ContainerError::Truncated { part: "header", .. })
        ),
        "{error}"
    );
}

#[test]
fn a_mismatched_file_is_refused_with_a_clear_error() {
    let weights = trained_weights(Backend::Flex);
    let error =
        PolicyWeights::new(weights.header().clone(), weights.values()[1..].to_vec()).unwrap_err();
    assert!(
        matches!(
            error,
            WeightsError::Format(ContainerError::CountMismatch { .. })
        ),
        "{error}"
    );
    let mut header = weights.header().clone();
    header.observation_dim = 30;
    let error = PolicyWeights::new(header, weights.values().to_vec()).unwrap_err();
    assert!(error.to_string().contains("observation_dim"), "{error}");
    let mut bytes = weights.to_bytes();
    bytes[0] = b'X';
    assert!(matches!(
        PolicyWeights::from_bytes(&bytes),
        Err(WeightsError::Format(ContainerError::BadMagic))
    ));
    let mut values = weights.values().to_vec();
    values[3] = f32::NAN;
    assert!(matches!(
        PolicyWeights::new(weights.header().clone(), values),
        Err(WeightsError::NotFinite(3))
    ));
}
