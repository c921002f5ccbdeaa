"""The built-in mazes, as JSON data files (read with ``MazeSpec.load(name)``)."""

__all__: list[str] = []
