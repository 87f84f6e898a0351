//! The label file: written and read back bit for bit, rejected with a named problem when
//! corrupt, merged from disjoint parts into the same bytes as one write.

use emg_kinematics::JointVector;
use emg_seeding::{Label, LabelError, LabelSet, TaskLabels};

fn sample_set(indices: &[u32]) -> LabelSet {
    let tasks = indices
        .iter()
        .map(|&task_index| TaskLabels {
            task_index,
            labels: (0..(task_index % 4))
                .map(|k| {
                    Label::stored(
                        JointVector::from_fn(|i, _| 0.1 * i as f64 + 0.01 * f64::from(task_index)),
                        1.0 - 0.1 * f64::from(k),
                        k,
                        0.003 * f64::from(k),
                    )
                })
                .collect(),
        })
        .collect();
    LabelSet::new([5; 32], 20, 6, tasks).expect("valid set")
}

/// A path named `name` inside a fresh temporary directory, which is removed on drop.
fn temporary(name: &str) -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    (dir, path)
}

#[test]
fn round_trip_is_exact() {
    let set = sample_set(&[0, 1, 2, 3, 7, 19]);
    let (_tmp, path) = temporary("round.labels");
    set.write(&path).unwrap();
    let back = LabelSet::read(&path).unwrap();
    assert_eq!(back, set);
    assert_eq!(back.get(7), set.get(7));
    assert!(back.get(4).is_none());
    assert!(!back.is_complete());
    let (_tmp_again, again) = temporary("round-again.labels");
    back.write(&again).unwrap();
    assert_eq!(
        std::fs::read(&path).unwrap(),
        std::fs::read(&again).unwrap()
    );
}

#[test]
fn merged_parts_equal_one_write() {
    let whole = sample_set(&(0..20).collect::<Vec<_>>());
    assert!(whole.is_complete());
    let parts = vec![
        sample_set(&[10, 11, 12, 13, 14, 15, 16, 17, 18, 19]),
        sample_set(&[0, 1, 2, 3, 4]),
        sample_set(&[5, 6, 7, 8, 9]),
    ];
    let merged = LabelSet::merge(parts).unwrap();
    let ((_tmp_a, a), (_tmp_b, b)) = (temporary("whole.labels"), temporary("merged.labels"));
    whole.write(&a).unwrap();
    merged.write(&b).unwrap();
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let overlapping = LabelSet::merge(vec![sample_set(&[1, 2]), sample_set(&[2, 3])]);
    assert!(matches!(
        overlapping,
        Err(LabelError::Record { task_index: 2, .. })
    ));
}

#[test]
fn bad_sets_and_files_are_rejected_by_name() {
    let unsorted = LabelSet::new(
        [0; 32],
        5,
        6,
        vec![TaskLabels {
            task_index: 1,
            labels: vec![
                Label::stored(JointVector::zeros(), 0.2, 0, 0.0),
                Label::stored(JointVector::zeros(), 0.5, 1, 0.0),
            ],
        }],
    );
    assert!(unsorted.unwrap_err().to_string().contains("longest first"));
    let beyond = LabelSet::new(
        [0; 32],
        5,
        6,
        vec![TaskLabels {
            task_index: 5,
            labels: vec![],
        }],
    );
    assert!(
        beyond
            .unwrap_err()
            .to_string()
            .contains("beyond the task set")
    );
    let nan = LabelSet::new(
        [0; 32],
        5,
        6,
        vec![TaskLabels {
            task_index: 0,
            labels: vec![Label::stored(JointVector::repeat(f64::NAN), 0.2, 0, 0.0)],
        }],
    );
    assert!(nan.unwrap_err().to_string().contains("'q' is not finite"));

    let (_tmp, path) = temporary("corrupt.labels");
    sample_set(&[1, 2, 3]).write(&path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() - 3]).unwrap();
    let error = LabelSet::read(&path).unwrap_err();
    assert!(error.to_string().contains("truncated"), "{error}");
    let mut wrong = bytes.clone();
    wrong[0] = b'X';
    std::fs::write(&path, &wrong).unwrap();
    assert!(
        LabelSet::read(&path)
            .unwrap_err()
            .to_string()
            .contains("magic")
    );
    let mut version = bytes;
    version[8] = 9;
    std::fs::write(&path, &version).unwrap();
    assert!(
        LabelSet::read(&path)
            .unwrap_err()
            .to_string()
            .contains("version 9")
    );
    assert!(matches!(
        LabelSet::read(&temporary("missing.labels").1),
        Err(LabelError::Io { .. })
    ));
}
