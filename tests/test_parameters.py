"""One schema for the controller's numbers: every slot of its Context parameter (control_law.LAW) has a doc and a
unit; the slots that copy the configuration take their declaration from params (`param`), whose bounds the
dataclasses enforce; docs/PARAMETERS.md is generated from it."""

import math
from dataclasses import fields
from pathlib import Path

from drake_biped import control_law as ctl
from drake_biped.controller import law_vector
from drake_biped.params import EpisodeConfig, parameter_info


def test_every_slot_has_a_doc_and_a_unit():
    assert all(f.doc and f.unit for f in ctl.LAW.fields)
    assert ctl.LAW.size == len(ctl.LAW.fields)  # every slot a scalar: each named once


def test_copied_slots_carry_their_declaration_and_value():
    config = EpisodeConfig()
    # move every copied number inside its bounds, so that a slot reading the wrong field shows
    changed = {}
    for i, (section, name, _) in enumerate(ctl.LAW_COPIED):
        lo, hi = parameter_info(type(getattr(config, section)), name)["bounds"]
        if name == "first_step":
            changed.setdefault(section, {})[name] = 2
            continue
        lo = -1.0 if lo is None else lo
        hi = lo + 2.0 if hi is None else hi
        changed.setdefault(section, {})[name] = lo + (hi - lo) * (0.13 + 0.017 * i)
    changed["window"]["end_s"] = changed["window"]["start_s"] + 0.1
    # every slot moved at once, the unread ones too (the servo leaves the motor's limit unread): a sampled point
    config = config.override({f"{s}.{n}": v for s, d in changed.items() for n, v in d.items()}, sampled=True)
    law = law_vector(config)
    for section, name, slot in ctl.LAW_COPIED:
        field = ctl.LAW.fields[ctl.LAW.offset(slot)]
        info = parameter_info(type(getattr(config, section)), name)
        assert field.unit == info["unit"] and field.bounds == info["bounds"] and info["doc"] in field.doc
        assert law[ctl.LAW.offset(slot)] == getattr(getattr(config, section), name), slot


def test_the_entrained_reading_drops_the_phase_condition():
    config = EpisodeConfig().override({"gait.phase_reading": "entrained"})
    assert law_vector(config)[ctl.LAW.offset("touchdown_min_phase")] == -math.inf


def test_docs_table_is_current():
    path = Path(__file__).resolve().parents[1] / "docs" / "PARAMETERS.md"
    assert path.read_text() == ctl.parameter_markdown(), "run `make docs-tables`"


def test_every_configuration_field_is_declared_once_with_its_meaning():
    from drake_biped.params import ContactParams, InitialConditions, Push

    for cls in (type(EpisodeConfig().cpg), type(EpisodeConfig().gait), InitialConditions, type(EpisodeConfig().window),
                type(EpisodeConfig().ground), Push, type(EpisodeConfig().sim), ContactParams):
        for f in fields(cls):
            info = parameter_info(cls, f.name)  # KeyError for a field not declared with param()
            assert info["doc"] and (info["unit"] or f.type in ("str", str)), f"{cls.__name__}.{f.name}"
