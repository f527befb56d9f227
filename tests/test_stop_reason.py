"""Why a run ended (mbs_models.stop_reason): every way is a member, written as the strings tables always held."""

from __future__ import annotations

import io
import json

import pandas as pd
import pytest

from mbs_models import StopReason

#: The strings results, JSON files and sweep tables have held since stop reasons exist (README, recorded baselines).
WRITTEN = {"END_TIME": "end_time", "METRICS_FINAL": "metrics_final", "NO_ENERGY_BOUND": "end_time_no_energy_bound",
           "ENERGY_CHECK": "end_time_energy_check", "AT_REST": "at_rest"}


def test_every_member_is_the_string_it_always_was():
    assert {member.name: member.value for member in StopReason} == WRITTEN
    for name, text in WRITTEN.items():
        member = StopReason[name]
        assert member == text and str(member) == text and f"{member}" == text and type(member.value) is str


@pytest.mark.parametrize("member", list(StopReason), ids=lambda m: m.name)
def test_every_member_has_a_one_line_message(member):
    assert member.message.strip() == member.message and member.message and "\n" not in member.message
    assert len({m.message for m in StopReason}) == len(StopReason)  # each says something of its own


def test_json_and_csv_write_the_strings_and_old_values_read_back():
    assert json.loads(json.dumps({"stop_reason": StopReason.AT_REST})) == {"stop_reason": "at_rest"}
    buffer = io.StringIO()
    pd.DataFrame({"stop_reason": list(StopReason)}).to_csv(buffer, index=False)
    assert buffer.getvalue().split() == ["stop_reason", *WRITTEN.values()]
    old = pd.read_csv(io.StringIO(buffer.getvalue()))["stop_reason"]  # a table written before the enumeration
    assert [StopReason(text) for text in old] == list(StopReason)
    with pytest.raises(ValueError):
        StopReason("stopped")
