"""Agents by name: what ``hippomaze dmtp --agent A`` and the benchmarks build agents with.

>>> from hippomaze.registry import agent_factory
>>> make = agent_factory("dqn", learning_rate=1e-3)
>>> agent = make(env.observation_space, env.action_space, seed=0)

Every factory is an :class:`~hippo_env.agent_protocol.AgentFactory`:
``factory(observation_space, action_space, seed=seed) -> agent``. Heavy imports (torch,
stable-baselines3, the hippocampal model) happen only when a factory is called.

Three ways to name an agent:

- a built-in name (:data:`AGENT_NAMES`);
- ``module:Class``, for any class that follows the Agent protocol, or ``module:make_agent`` for a
  factory function (an :class:`~hippo_env.agent_protocol.AgentFactory`); ``hippomaze dmtp`` puts the
  current directory on the import path, as ``python -m`` does;
- a name another distribution registers in the ``hippomaze.agents`` entry-point group, e.g. in its
  ``pyproject.toml``::

      [project.entry-points."hippomaze.agents"]
      greedy = "mypackage.agents:GreedyAgent"

  after which ``hippomaze dmtp --agent greedy`` builds ``GreedyAgent``.

A class or factory may declare ``env_kwargs`` (e.g. ``env_kwargs = {"odometry": True}``), the
arguments its agent needs ``gym.make`` to be given; the factory returned here carries them, and the
runner passes them on, as it does for the built-in agents.
"""

from __future__ import annotations

import importlib
import inspect
from importlib.metadata import entry_points
from importlib.util import find_spec
from typing import Any

import gymnasium as gym

from hippo_env.agent_protocol import AgentFactory, missing_methods

#: The entry-point group third-party agents register under.
ENTRY_POINT_GROUP = "hippomaze.agents"

#: The built-in agent names. ``dynaq`` is PRIVILEGED (it reads the true position).
AGENT_NAMES: tuple[str, ...] = ("hippo", "hippo-paper", "random", "dqn", "ppo", "dynaq")

#: Agents that read ``info["position"]`` (shown as "privileged" in every table).
PRIVILEGED: frozenset[str] = frozenset({"dynaq"})


def _hippo(paper: bool = False, **overrides: Any) -> AgentFactory:
    """The hippocampal agent: the default (improved) model, or with ``paper`` the paper's model
    (``AgentConfig.paper()``). The factory's ``env_kwargs`` asks the runner for the odometry
    sensor when the model path-integrates."""
    try:
        from hippo_agent import AgentConfig
    except ImportError as err:
        raise ImportError(f"agent 'hippo' needs the hippo_agent package, which did not import: {err}") from err
    config = (AgentConfig.paper() if paper else AgentConfig()).with_values(overrides)  # dotted names: "model.n_place"

    def make(observation_space: gym.spaces.Space, action_space: gym.spaces.Space, *, seed: int) -> Any:
        from hippo_agent import HippocampalAgent

        return HippocampalAgent(observation_space, action_space, config=config, seed=seed)

    make.env_kwargs = {"odometry": True} if config.path_integration is not None else {}  # type: ignore[attr-defined]
    return make


def _random(**overrides: Any) -> AgentFactory:
    if overrides:
        raise ValueError(f"the random agent takes no parameters, got {', '.join(sorted(overrides))}")

    def make(observation_space: gym.spaces.Space, action_space: gym.spaces.Space, *, seed: int) -> Any:
        from hippomaze.baselines.random_agent import RandomAgent

        return RandomAgent(observation_space, action_space, seed=seed)

    return make


def _sb3(name: str, **overrides: Any) -> AgentFactory:
    from hippomaze.baselines.hyperparams import make_params
    from hippomaze.baselines.sb3_agents import INSTALL_HINT

    params = make_params(name, **overrides)  # check the names now, not at the first call
    missing = [package for package in ("torch", "stable_baselines3") if find_spec(package) is None]
    if missing:  # found without importing them: the imports are heavy
        raise ImportError(f"agent {name!r} needs torch and stable-baselines3 (the 'baselines' extra), not installed here: {INSTALL_HINT}")

    def make(observation_space: gym.spaces.Space, action_space: gym.spaces.Space, *, seed: int) -> Any:
        from hippomaze.baselines.sb3_agents import DQNAgent, PPOAgent

        cls = DQNAgent if name == "dqn" else PPOAgent
        return cls(observation_space, action_space, seed=seed, params=params)

    return make


def _dynaq(**overrides: Any) -> AgentFactory:
    from hippomaze.baselines.hyperparams import make_params

    params = make_params("dynaq", **overrides)

    def make(observation_space: gym.spaces.Space, action_space: gym.spaces.Space, *, seed: int) -> Any:
        from hippomaze.baselines.dynaq import DynaQAgent

        return DynaQAgent(observation_space, action_space, seed=seed, params=params)

    return make


def _takes_seed(name: str, build: Any, overrides: dict[str, Any]) -> bool:
    """Whether ``build(observation_space, action_space, seed=..., **overrides)`` fits ``build``, an
    agent class or factory function.

    One without ``seed`` is accepted (the agent is then seeded only by what it does itself); one
    that cannot take the two spaces is a one-line ``TypeError`` naming the expected signature.
    """
    try:
        signature = inspect.signature(build)
    except (TypeError, ValueError):  # no introspectable signature: assume the documented one
        return True
    for with_seed in (True, False):
        try:
            signature.bind(None, None, **({"seed": 0} if with_seed else {}), **overrides)
        except TypeError:
            continue
        return with_seed
    extra = f", {', '.join(f'{k}=...' for k in overrides)}" if overrides else ""
    shown = getattr(build, "__name__", type(build).__name__)
    expected = (
        "an agent class's constructor must be __init__(self, observation_space, action_space, seed=None)"
        if inspect.isclass(build)
        else "an agent factory must be make_agent(observation_space, action_space, *, seed)"
    )
    raise TypeError(
        f"agent {name!r}: {shown}{signature} cannot be called as {shown}(observation_space, action_space, seed=seed{extra}); {expected}"
    )


def _declared_env_kwargs(name: str, build: Any) -> dict[str, Any]:
    """The ``env_kwargs`` an agent class or factory declares (``{}`` if none), checked to be a dict of names."""
    declared = getattr(build, "env_kwargs", None)
    if declared is None:
        return {}
    if not isinstance(declared, dict) or not all(isinstance(k, str) for k in declared):
        raise TypeError(f"agent {name!r}: env_kwargs must be a dict of gym.make arguments, e.g. {{'odometry': True}}; got {declared!r}")
    return dict(declared)


def _factory(name: str, build: Any, overrides: dict[str, Any]) -> AgentFactory:
    """The factory for an agent class or factory function ``build``, carrying its declared ``env_kwargs``."""
    takes_seed = _takes_seed(name, build, overrides)

    def make(observation_space: gym.spaces.Space, action_space: gym.spaces.Space, *, seed: int) -> Any:
        if takes_seed:
            return build(observation_space, action_space, seed=seed, **overrides)
        return build(observation_space, action_space, **overrides)

    make.env_kwargs = _declared_env_kwargs(name, build)  # type: ignore[attr-defined]
    return make


def agent_factory(name: str, **overrides: Any) -> AgentFactory:
    """A factory ``factory(observation_space, action_space, seed=seed) -> agent`` for the agent ``name``.

    Args:
        name: ``hippo`` (the default model), ``hippo-paper`` (``AgentConfig.paper()``), ``random``,
            ``dqn``, ``ppo``, ``dynaq`` (privileged: reads the true position),
            a name registered in the ``hippomaze.agents`` entry-point group, ``module:Class``
            for any class following the Agent protocol (either built as
            ``Class(observation_space, action_space, seed=seed, **overrides)``, or without
            ``seed`` if its constructor takes none), or ``module:make_agent`` for a factory
            function, called the same way. A class's or factory's ``env_kwargs`` attribute
            becomes the returned factory's.
        **overrides: Parameters to change: for ``hippo``, fields of ``hippo_agent.AgentConfig`` by dotted name
            (``**{"model.n_place": 500, "homing": None}``, see ``AgentConfig.with_values``); of
            :mod:`hippomaze.baselines.hyperparams` ``DQNParams`` / ``PPOParams`` / ``DynaQParams`` for the others.

    Raises:
        ValueError: An unknown name (the message lists the allowed ones) or parameter.
        TypeError: A name that is not a string, a parameter of the wrong type, or a
            ``module:Class`` that is not an agent or whose constructor cannot take
            ``(observation_space, action_space)``.
        ImportError: ``dqn`` or ``ppo`` without torch and stable-baselines3 (the message says how to install them).
    """
    if not isinstance(name, str):
        raise TypeError(f"agent name must be a string, got {name!r}; choose one of {', '.join(AGENT_NAMES)} or module:Class")
    if name in ("hippo", "hippo-paper"):
        return _hippo(paper=name == "hippo-paper", **overrides)
    if name == "random":
        return _random(**overrides)
    if name in ("dqn", "ppo"):
        return _sb3(name, **overrides)
    if name == "dynaq":
        return _dynaq(**overrides)
    registered = {ep.name: ep for ep in entry_points(group=ENTRY_POINT_GROUP)}
    if ":" in name or name in registered:
        build = load_agent(name) if ":" in name else _load_registered(name, registered[name])
        return _factory(name, build, overrides)
    hint = " (dense reward is an env setting: reward_type='dense', not an agent)" if name.endswith("-dense") else ""
    others = f", one registered by an installed package ({', '.join(sorted(registered))})" if registered else ""
    raise ValueError(f"agent {name!r} is unknown{hint}; choose one of {', '.join(AGENT_NAMES)}{others}, or module:Class for your own")


def load_agent(spec: str) -> Any:
    """Import ``module:Class`` (e.g. ``mypkg.agents:GreedyAgent``) or ``module:make_agent`` (a factory
    function); a class is checked to follow the Agent protocol."""
    if ":" not in spec:
        raise ValueError(f"agent {spec!r} is unknown; give hippo, random, dqn, ppo, or module:Class for your own")
    module_name, _, attribute = spec.partition(":")
    try:
        module = importlib.import_module(module_name)
    except ImportError as err:
        raise ValueError(f"agent {spec!r}: cannot import module {module_name!r} ({err})") from err
    build = getattr(module, attribute, None)
    if build is None:
        raise ValueError(f"agent {spec!r}: module {module_name!r} has no attribute {attribute!r}")
    return _checked(spec, build)


def _load_registered(name: str, entry_point: Any) -> Any:
    """The class or factory an installed package registered as ``name`` in the ``hippomaze.agents`` group."""
    try:
        build = entry_point.load()
    except Exception as err:  # a broken third-party package: say which and why
        raise ValueError(f"agent {name!r} (entry point {entry_point.value!r} in group {ENTRY_POINT_GROUP!r}) did not load: {err}") from err
    return _checked(f"{name} ({entry_point.value})", build)


def _checked(spec: str, build: Any) -> Any:
    """``build`` if it is an agent class following the protocol or a factory (any other callable)."""
    if inspect.isclass(build):
        missing = missing_methods(build)
        if missing:
            raise TypeError(
                f"agent {spec!r} does not follow the Agent protocol: it lacks {', '.join(missing)} (see hippo_env.agent_protocol)"
            )
        return build
    if callable(build):
        return build  # a factory: the runner checks the agents it returns
    raise TypeError(
        f"agent {spec!r} is a {type(build).__name__}, neither an agent class nor a factory function; name a class following the "
        "Agent protocol (see hippo_env.agent_protocol) or a factory make_agent(observation_space, action_space, *, seed)"
    )


__all__ = ["AGENT_NAMES", "ENTRY_POINT_GROUP", "PRIVILEGED", "agent_factory", "load_agent"]
