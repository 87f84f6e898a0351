//! Buckets and cell statistics of the evaluation protocol on hand-checked data.

use emg_eval::{BucketConfig, Difficulty, bucket_members, cell_stats};

#[test]
fn buckets_follow_the_paper_thresholds() {
    let config = BucketConfig::default();
    assert_eq!(config.classify(0.80), Difficulty::Easy);
    assert_eq!(config.classify(0.7999), Difficulty::Medium);
    assert_eq!(config.classify(0.45), Difficulty::Medium);
    assert_eq!(config.classify(0.4499), Difficulty::Difficult);
    let members = bucket_members(&[0.9, 0.5, 0.2, 1.2, 0.44], &config);
    assert_eq!(
        members,
        vec![
            (Difficulty::Easy, vec![0, 3]),
            (Difficulty::Medium, vec![1]),
            (Difficulty::Difficult, vec![2, 4]),
        ]
    );
}

#[test]
fn cell_statistics_use_only_the_members() {
    let lengths = [0.5, 0.2, 1.0, 0.4];
    let references = [1.0, 0.4, 0.8, 0.4];
    let stats = cell_stats(&lengths, &references, &[0, 2]).expect("two members");
    assert_eq!(stats.length_m.count, 2);
    assert!((stats.length_m.mean - 0.75).abs() < 1e-12);
    assert!((stats.ratio_percent.mean - (50.0 + 125.0) / 2.0).abs() < 1e-9);
    assert!((stats.ratio_percent.max - 125.0).abs() < 1e-9);
    assert!(cell_stats(&lengths, &references, &[]).is_none());
}
