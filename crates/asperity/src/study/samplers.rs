//! The samplers behind each [`Method`]: a realisation's force–stiffness curve.

use super::{Method, ProgressFn, StudyDir, StudySpec, Task, TaskResult};
use crate::{Error, Result};

/// Runs (or resumes) `task` with the sampler of `spec.method`.
pub fn run_any_task(
    spec: &StudySpec,
    task: Task,
    store: &StudyDir,
    progress: &ProgressFn,
) -> Result<TaskResult> {
    let _ = (task, store, progress);
    match spec.method {
        Method::Mdr | Method::Bem => Err(Error::invalid("method", "solver not wired yet")),
    }
}
