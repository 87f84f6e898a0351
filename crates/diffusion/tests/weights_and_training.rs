//! The plain forward agrees with the Burn model on both backends; a resumed run continues the
//! same loss curve; damaged or mismatched weights files give clear errors.

use burn::module::Module;
use burn::tensor::{Tensor, TensorData};
use emg_diffusion::{
    Backend, ContainerError, DenoiserInput, DenoiserWeights, DiffusionConfig, ForwardScratch,
    PlainDenoiser, TrainConfig, Trainer, TrainingSet, WeightsError, sinusoidal_embedding,
};

fn tiny() -> DiffusionConfig {
    DiffusionConfig {
        data_dim: 3,
        condition_dim: 4,
        width: 16,
        hidden: 24,
        blocks: 2,
        time_dim: 8,
        timesteps: 50,
    }
}

fn toy_data() -> TrainingSet {
    let n = 64;
    let conditions: Vec<f32> = (0..n * 4)
        .map(|i| ((i * 37 % 17) as f32 / 8.5) - 1.0)
        .collect();
    let samples: Vec<f32> = (0..n * 3)
        .map(|i| ((i * 11 % 13) as f32 / 6.5) - 1.0)
        .collect();
    TrainingSet::new(conditions, samples, 4, 3, "toy").unwrap()
}

fn training(steps: usize) -> TrainConfig {
    TrainConfig {
        steps,
        batch_size: 16,
        log_every_steps: 1,
        learning_rate: 1e-3,
        ..TrainConfig::default()
    }
}

fn plain_matches_burn(backend: Backend) {
    let data = toy_data();
    let mut trainer = Trainer::new(tiny(), training(3), backend, &data).unwrap();
    for _ in 0..3 {
        trainer.train_step(&data);
    }
    let weights = trainer.current_weights();
    let device = backend.device();
    let model = weights.to_model(&device);
    let rows = 5;
    let samples: Vec<f32> = (0..rows * 3).map(|i| libm::sinf(i as f32 * 0.37)).collect();
    let conditions: Vec<f32> = (0..rows * 4).map(|i| libm::cosf(i as f32 * 0.91)).collect();
    let dropped = [0.0f32, 1.0, 0.0, 1.0, 0.0];
    let t = 31;
    let mut times = vec![0.0f32; rows * 8];
    for row in times.chunks_exact_mut(8) {
        sinusoidal_embedding(t, row);
    }
    let tensor =
        |v: Vec<f32>, shape: [usize; 2]| Tensor::<2>::from_data(TensorData::new(v, shape), &device);
    let burn_out = model.valid().forward(DenoiserInput {
        sample: tensor(samples.clone(), [rows, 3]),
        time_embedding: tensor(times, [rows, 8]),
        condition: tensor(conditions.clone(), [rows, 4]),
        condition_dropped: tensor(dropped.to_vec(), [rows, 1]),
        dropout_masks: None,
    });
    let burn_out = burn_out.into_data().as_slice::<f32>().unwrap().to_vec();

    let plain = PlainDenoiser::new(&weights);
    let mut embeddings = vec![0.0f32; rows * 16];
    for (i, row) in embeddings.chunks_exact_mut(16).enumerate() {
        if dropped[i] == 1.0 {
            row.copy_from_slice(plain.null_embedding());
        } else {
            plain.embed_condition(&conditions[i * 4..(i + 1) * 4], row);
        }
    }
    let mut out = vec![0.0f32; rows * 3];
    plain.velocity(
        t,
        &samples,
        &embeddings,
        rows,
        &mut ForwardScratch::default(),
        &mut out,
    );
    for (a, b) in out.iter().zip(&burn_out) {
        assert!(
            (a - b).abs() < 1e-4 * (1.0 + b.abs()),
            "{backend:?}: plain {a} vs burn {b}"
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
fn resumed_run_continues_the_same_loss_curve() {
    let data = toy_data();
    let mut straight = Trainer::new(tiny(), training(12), Backend::Flex, &data).unwrap();
    for _ in 0..12 {
        straight.train_step(&data);
    }
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("checkpoint");
    let mut first = Trainer::new(tiny(), training(12), Backend::Flex, &data).unwrap();
    for _ in 0..6 {
        first.train_step(&data);
    }
    first.save_checkpoint(&dir).unwrap();
    drop(first);
    let mut resumed = Trainer::resume(&dir, tiny(), training(12), Backend::Flex, &data).unwrap();
    assert_eq!(resumed.step_count(), 6);
    for _ in 0..6 {
        resumed.train_step(&data);
    }
    let (a, b) = (straight.loss_log(), resumed.loss_log());
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(b) {
        assert_eq!(x.step, y.step);
        assert!(
            (x.loss - y.loss).abs() <= 1e-6 * x.loss.abs(),
            "step {}: {} vs {}",
            x.step,
            x.loss,
            y.loss
        );
    }
    let (ea, eb) = (
        straight.ema_weights().values(),
        resumed.ema_weights().values(),
    );
    assert!(
        ea.iter()
            .zip(eb)
            .all(|(x, y)| (x - y).abs() <= 1e-5 * (1.0 + x.abs()))
    );

    let other = TrainConfig {
        seed: 9,
        ..training(12)
    };
    let mismatch = Trainer::resume(&dir, tiny(), other, Backend::Flex, &data);
    assert!(
        mismatch
            .err()
            .unwrap()
            .to_string()
            .contains("training config")
    );
}

#[test]
fn damaged_or_mismatched_weights_files_give_clear_errors() {
    let data = toy_data();
    let trainer = Trainer::new(tiny(), training(1), Backend::Flex, &data).unwrap();
    let weights = trainer.ema_weights().clone();
    let bytes = weights.to_bytes();
    assert_eq!(DenoiserWeights::from_bytes(&bytes).unwrap(), weights);

    for cut in [0, 5, 12, 40, bytes.len() / 2, bytes.len() - 1] {
        let error = DenoiserWeights::from_bytes(&bytes[..cut]).unwrap_err();
        assert!(
            matches!(
                error,
                WeightsError::Format(ContainerError::Truncated { .. })
            ),
            "cut at {cut}: {error}"
        );
        assert!(
            error
                .to_string()
                .contains("not a valid denoiser weights file")
        );
        let cause = std::error::Error::source(&error)
            .expect("the container error")
            .to_string();
        assert!(cause.contains("truncated"), "{cause}");
    }
    let mut padded = bytes.clone();
    padded.push(0);
    assert!(matches!(
        DenoiserWeights::from_bytes(&padded),
        Err(WeightsError::Format(ContainerError::TrailingBytes(1)))
    ));
    let mut bad_magic = bytes.clone();
    bad_magic[0] = b'X';
    assert!(matches!(
        DenoiserWeights::from_bytes(&bad_magic),
        Err(WeightsError::Format(ContainerError::BadMagic))
    ));

    // A header whose network shape does not fit the values.
    let mut header = weights.header().clone();
    header.config.width = 17;
    let error = DenoiserWeights::new(header, weights.values().to_vec()).unwrap_err();
    assert!(
        matches!(
            error,
            WeightsError::Format(ContainerError::CountMismatch { .. })
        ),
        "{error}"
    );

    // Weights of another dimension than the caller needs.
    let error = weights.require_dimensions(7, 9).unwrap_err();
    assert_eq!(
        error.to_string(),
        "weights field 'config.data_dim' is 3, but 7 is required"
    );

    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("denoiser.weights");
    weights.write(&path).unwrap();
    assert_eq!(DenoiserWeights::read(&path).unwrap(), weights);
    std::fs::write(&path, &bytes[..bytes.len() - 3]).unwrap();
    assert!(matches!(
        DenoiserWeights::read(&path),
        Err(WeightsError::Format(ContainerError::Truncated {
            part: "values",
            ..
        }))
    ));
    std::fs::remove_file(&path).ok();
    let missing = DenoiserWeights::read(&path).unwrap_err();
    assert!(missing.to_string().contains(&path.display().to_string()));
}
