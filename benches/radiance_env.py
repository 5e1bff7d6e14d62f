"""The environment the benchmark scripts run Radiance in: pyradiance's Radiance 6 `bin/`
first on PATH, RAYPATH its `lib/` (after the working folder, as Radiance expects)."""
import os


def radiance_env():
    import pyradiance

    root = os.path.dirname(pyradiance.__file__)
    env = dict(os.environ)
    env["PATH"] = os.path.join(root, "bin") + os.pathsep + env.get("PATH", "")
    env["RAYPATH"] = "." + os.pathsep + os.path.join(root, "lib")
    return env
