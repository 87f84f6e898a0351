//! The journaled labeller: an interrupted run resumes to the same file, shards merged equal the
//! single run byte for byte, and the thread count changes nothing.

mod common;

use common::{eval_path, eval_tasks, robot, small_config, temporary_dir};
use emg_seeding::{LabelJob, Shard, file_sha256};

const TASKS: usize = 7;
const CHUNK: usize = 2;

fn label_file(dir: &std::path::Path, runs: &[(Shard, Option<usize>)], threads: usize) -> Vec<u8> {
    let (robot, config) = (robot(), small_config());
    let tasks = eval_tasks(&robot, TASKS);
    let sha = file_sha256(&eval_path()).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    for (shard, limit) in runs {
        // A fresh job per run, as a restarted process would build it.
        let job = LabelJob::new(&robot, &tasks, sha, &config, dir, CHUNK).unwrap();
        pool.install(|| job.run(*shard, *limit, &|_| {})).unwrap();
    }
    let job = LabelJob::new(&robot, &tasks, sha, &config, dir, CHUNK).unwrap();
    let (set, stats) = job.merge().unwrap();
    assert!(set.is_complete());
    assert_eq!(stats.len(), TASKS);
    let path = dir.join("merged.labels");
    set.write(&path).unwrap();
    std::fs::read(path).unwrap()
}

#[test]
fn interrupted_sharded_and_threaded_runs_equal_the_single_run() {
    let single = label_file(temporary_dir("single").path(), &[(Shard::WHOLE, None)], 1);

    // Interrupted after one chunk, then after one more, then resumed to the end.
    let tmp = temporary_dir("resumed");
    let dir = tmp.path();
    {
        let (robot, config) = (robot(), small_config());
        let tasks = eval_tasks(&robot, TASKS);
        let sha = file_sha256(&eval_path()).unwrap();
        let job = LabelJob::new(&robot, &tasks, sha, &config, dir, CHUNK).unwrap();
        let first = job.run(Shard::WHOLE, Some(1), &|_| {}).unwrap();
        assert_eq!((first.chunks_done, first.chunks_left), (1, 3));
        assert!(job.merge().is_err(), "an incomplete journal must not merge");
        let second = job.run(Shard::WHOLE, Some(1), &|_| {}).unwrap();
        assert_eq!((second.chunks_skipped, second.chunks_left), (1, 2));
    }
    let resumed = label_file(dir, &[(Shard::WHOLE, None)], 2);
    assert_eq!(single, resumed, "resumed run differs from the single run");

    let sharded = label_file(
        temporary_dir("sharded").path(),
        &[
            ("1/3".parse().unwrap(), None),
            ("0/3".parse().unwrap(), None),
            ("2/3".parse().unwrap(), None),
        ],
        2,
    );
    assert_eq!(single, sharded, "merged shards differ from the single run");
}

#[test]
fn journal_of_another_config_is_refused_and_shards_parse() {
    let (robot, config) = (robot(), small_config());
    let tasks = eval_tasks(&robot, 3);
    let sha = file_sha256(&eval_path()).unwrap();
    let tmp = temporary_dir("refused");
    let dir = tmp.path();
    LabelJob::new(&robot, &tasks, sha, &config, dir, CHUNK).unwrap();
    let mut other = config.clone();
    other.seed += 1;
    let error = LabelJob::new(&robot, &tasks, sha, &other, dir, CHUNK)
        .err()
        .unwrap();
    assert!(error.to_string().contains("another task set"), "{error}");
    assert_eq!("2/5".parse::<Shard>(), Ok(Shard { index: 2, count: 5 }));
    assert!("5/5".parse::<Shard>().is_err());
    let error = "x/2".parse::<Shard>().unwrap_err().to_string();
    assert!(
        error.contains("'x/2'") && error.contains("whole numbers"),
        "{error}"
    );
}
