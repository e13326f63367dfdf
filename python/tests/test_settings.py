"""The package's keywords against the library's settings schema (``toposmooth.SETTINGS``, from
which the CLI's flags are made): a setting added to one front end only fails here. Then the
values' types, checked as the CLI's text is: a number is not a string, a count not a float."""

import inspect

import numpy as np
import pytest

import toposmooth

SCHEMA = {s["name"]: s for s in toposmooth.SETTINGS}
SELECTION = [s["name"] for s in toposmooth.SETTINGS if s["group"] == "selection"]

#: Keywords of smooth() that are not settings of the run: the domain, the input's handling,
#: watching the call.
NOT_SETTINGS = {"values", "x", "spacing", "origin", "vertices", "faces", "fill_missing", "mask", "progress", "cancel"}


def as_python(setting, text):
    """The schema's default text as the Python keyword's default."""
    if text is None:
        return None
    kind = setting["kind"]
    if kind == "switch":
        return text == "true"
    if kind == "count":
        return int(text)
    if kind == "real":
        return float(text)
    if kind == "orders":
        return int(text) if text.isdigit() else text
    return text


def keywords(function):
    return {
        name: p.default
        for name, p in inspect.signature(function).parameters.items()
        if p.kind in (p.KEYWORD_ONLY, p.POSITIONAL_OR_KEYWORD) and name not in NOT_SETTINGS
    }


def test_smooth_takes_exactly_the_schema_s_settings_with_its_defaults():
    given = keywords(toposmooth.smooth)
    assert sorted(given) == sorted(SCHEMA), "smooth()'s keywords and toposmooth.SETTINGS differ"
    for name, default in given.items():
        assert default == as_python(SCHEMA[name], SCHEMA[name]["default"]), name
        assert type(default) is type(as_python(SCHEMA[name], SCHEMA[name]["default"])), name


def test_extrema_takes_the_selection_and_smoother_every_setting():
    given = keywords(toposmooth.extrema)
    assert sorted(given) == sorted(SELECTION)
    for name in SCHEMA:
        # each setting is accepted by the Smoother (the keywords go through **settings)
        value = {"threshold": "5%", "count": 3, "real": 0.5, "switch": True, "indices": [0],
                 "orders": 2, "size": "1G"}.get(SCHEMA[name]["kind"], (SCHEMA[name].get("choices") or [None])[0])
        settings = {name: value}
        if SCHEMA[name]["partner"]:
            settings[SCHEMA[name]["partner"]] = value
        try:
            toposmooth.Smoother((12, 12), **settings)
        except toposmooth.UsageError as e:  # a valid value of each kind is accepted
            pytest.fail(f"{name}={value!r}: {e}")
    with pytest.raises(toposmooth.UsageError, match="unknown setting"):
        toposmooth.Smoother((12, 12), gamma=1.0)


def test_the_schema_describes_each_kind():
    assert SCHEMA["edges"]["choices"] == ["minimal", "all"]
    assert SCHEMA["solver"]["default"] == "auto"
    assert SCHEMA["max_iter"]["min"] == 1
    assert SCHEMA["minima"]["partner"] == "maxima" and SCHEMA["keep_max"]["partner"] == "keep_min"
    assert SCHEMA["data_weight"]["inclusive"] is True and SCHEMA["smooth_length"]["inclusive"] is False
    assert all(s["help"] for s in toposmooth.SETTINGS)


@pytest.mark.parametrize(
    "settings, words",
    [
        (dict(data_weight="1"), "data_weight: expected a number"),
        (dict(data_weight=True), "data_weight: expected a number"),
        (dict(minima=2.0, maxima=1), "minima: expected a whole number"),
        (dict(max_iter=0), "between 1 and"),
        (dict(keep_min="0,3", keep_max=[5]), "keep_min: expected a list of vertex indices"),
        (dict(keep_min=[0.5], keep_max=[5]), "keep_min: expected a list"),
        (dict(keep_min=[-1], keep_max=[5]), "not a vertex index"),
        (dict(edges="some"), "must be one of minimal, all"),
        (dict(persistence="5%", pairs=2), "one selection rule"),
        (dict(minima=2), "needs maxima"),
        (dict(threads=0), "between 1 and"),
        (dict(order=7), "order"),
    ],
)
def test_wrong_values_are_usage_errors_naming_the_setting(settings, words):
    h = np.sin(np.linspace(0, 9, 200))
    with pytest.raises(toposmooth.UsageError, match=words):
        toposmooth.smooth(h, **settings)


def test_numpy_values_are_taken_as_their_numbers():
    t = np.linspace(0, 6 * np.pi, 300)
    h = np.sin(t) + 0.1 * np.sin(23 * t)
    a = toposmooth.smooth(h, pairs=np.int64(3), data_weight=np.float32(0.5), keep_all_maxima=np.False_)
    b = toposmooth.smooth(h, pairs=3, data_weight=0.5)
    assert np.array_equal(a.smoothed, b.smoothed)
    c = toposmooth.smooth(h, keep_min=np.array([0]), keep_max=np.array([b.kept_maxima[0]]))
    assert c.kept_minima.tolist() == [0]


def test_read_takes_exactly_the_input_options_of_the_cli():
    names = [o["name"] for o in toposmooth.INPUT_OPTIONS]
    params = [n for n in inspect.signature(toposmooth.read).parameters if n != "path"]
    assert params == names, "read()'s keywords and the library's input options (the CLI's input flags) differ"
    for name, p in inspect.signature(toposmooth.read).parameters.items():
        if name != "path":
            switch = next(o["switch"] for o in toposmooth.INPUT_OPTIONS if o["name"] == name)
            assert p.default == (False if switch else None), name


def test_a_run_predicted_past_its_memory_limit_raises_memory_limit_error(datasets):
    h = np.genfromtxt(datasets / "soapfilm_piv_vorticity_63x63.csv", delimiter=",")
    with pytest.raises(toposmooth.MemoryLimitError) as e:
        toposmooth.smooth(h, fill_missing=True, memory_limit="4M")
    assert isinstance(e.value, MemoryError) and e.value.exit_code == 3
    assert "over the memory budget of 4 MiB" in str(e.value)
    r = toposmooth.smooth(h, fill_missing=True, memory_limit=2 << 30)
    assert r.report["memory"]["budget"] == 2 << 30 and r.report["memory"]["predicted_peak"] > 0
