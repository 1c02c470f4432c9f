"""present.jsonout.json_of writes what json.dumps(to_jsonable(obj), indent=...) writes (the oracle),
character for character, float arrays included."""

import json

import numpy as np
import pytest

from screwkin.present.jsonout import json_of, json_text, to_jsonable


def samples():
    rng = np.random.default_rng(0)
    return [
        {"rows": rng.normal(size=(7, 3)), "flat": rng.normal(size=5), "one": rng.normal(size=(4, 1)),
         "nested": {"empty": np.zeros((0, 3)), "inf": np.array([1.0, np.inf]), "ints": np.arange(3),
                    "lists": [[1.0, 2.0], [3.0, -0.0]], "ragged": [[1.0], []], 3: "an int key"}},
        {"f32": {"a": rng.normal(size=(2, 2)).astype(np.float32)}, "none": {}, "empty": [], "scalar": np.float64(2.5),
         "zero_d": np.array(3.0), "tiny": np.array([1e-300, 5e-324, 1e300]), "text": 'a "quoted"\nline'},
        rng.normal(size=(3, 2)), [rng.normal(size=2)], {"only": rng.normal(size=(1, 1))}, {}, 1.5,
    ]


@pytest.mark.parametrize("indent", [2, 4])
def test_json_of_is_json_dumps_of_to_jsonable(indent):
    for obj in samples():
        expected = json.dumps(to_jsonable(obj), indent=indent)
        assert json_of(obj, indent) == expected
        assert json_text(to_jsonable(obj), indent) == expected


def test_nan_is_null_and_infinity_a_string():
    """The one rule (README, "Command line"): a value that does not exist (NaN) is null, an infinite
    one "inf" or "-inf" -- in arrays, lists, scalars and numpy scalars alike; sorted keys and one line
    as json.dumps writes them."""
    obj = {"b": {"a": np.array([1.0, np.nan, np.inf]), "c": [float("-inf"), float("nan")], "d": np.float64("nan")},
           "a": np.array([[np.nan, 1.0], [2.0, -np.inf]])}
    expected = {"b": {"a": [1.0, None, "inf"], "c": ["-inf", None], "d": None}, "a": [[None, 1.0], [2.0, "-inf"]]}
    assert json.loads(json_of(obj)) == expected
    assert json_of(obj, indent=1, sort_keys=True) == json.dumps(expected, indent=1, sort_keys=True)
    assert json_of(obj, indent=None) == json.dumps(expected)
