"""Put this directory on PYTHONPATH when ParaView 5.11 runs on Python 3.11 (Debian bookworm's
python3-paraview): ParaView's Python-plugin loader imports ``inspect.getargspec``, which Python
3.11 removed, before it reads any plugin, so no Python plugin loads without it. It uses only
``.args``, which ``inspect.getfullargspec`` has too."""

import inspect

if not hasattr(inspect, "getargspec"):
    inspect.getargspec = inspect.getfullargspec
