"""The step ledger of a job: the agent wrapper that counts dry-run steps and continues a life, and the progress file."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from hippo_env.dmtp import dry_run_method


class Ledger:
    """Wraps an agent for the runner: counts its dry-run steps, and can continue a life.

    ``dry_run`` and ``start_trial`` exist on the wrapper only if the agent has them (the runner
    looks them up with ``getattr``). ``skip_dry_run`` hides ``dry_run`` (an agent that lives on into
    a goal-switch trial does not get a second dry run); ``trial_offset`` numbers its trials on.
    """

    def __init__(self, agent: Any, progress: Any = None) -> None:
        self.agent = agent
        self.dry_run_steps = 0
        self.skip_dry_run = False
        self.trial_offset = 0
        self.progress = progress

    def reset(self, observation: Any, info: dict[str, Any]) -> None:
        self.agent.reset(observation, info)

    def act(self, observation: Any) -> Any:
        return self.agent.act(observation)

    def observe(self, action: Any, observation: Any, reward: float, terminated: bool, truncated: bool, info: dict[str, Any]) -> None:
        self.agent.observe(action, observation, reward, terminated, truncated, info)
        if self.progress is not None:
            self.progress.step()

    def __getattr__(self, name: str) -> Any:
        if name == "dry_run" and not self.skip_dry_run:
            agent_dry_run = dry_run_method(self.agent)
            if agent_dry_run is not None:

                def dry_run(env: Any) -> None:
                    before = env.steps
                    agent_dry_run(env)
                    self.dry_run_steps += env.steps - before
                    if self.progress is not None:
                        self.progress.step(env.steps - before)

                return dry_run
        if name == "start_trial" and callable(getattr(self.agent, "start_trial", None)):
            return lambda trial: self.agent.start_trial(trial + self.trial_offset)
        raise AttributeError(name)


class ProgressFile:
    """Writes a job's step count to a small file now and then, for the driver's progress bar."""

    def __init__(self, path: str | None, every: int = 2000) -> None:
        self.path = path
        self.every = every
        self.steps = 0
        self._last = 0

    def step(self, n: int = 1) -> None:
        self.steps += n
        if self.path and self.steps - self._last >= self.every:
            self._last = self.steps
            try:
                Path(self.path).write_text(str(self.steps))
            except OSError:
                pass
