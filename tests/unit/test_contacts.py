"""Local contact dumps and force-chain segments."""

import numpy as np
import pytest

from siloflow.engines.liggghts.contacts import ContactDumpError, parse_local_dump, read_contacts
from siloflow.analysis.numerics.force_chains import all_force_chains, force_chain_segments

DUMP = """ITEM: TIMESTEP
22000
ITEM: NUMBER OF ENTRIES
2
ITEM: BOX BOUNDS ff ff ff
-0.04 0.04
0 0.01
-0.03 0.2
ITEM: ENTRIES c_contacts[1] c_contacts[2] c_contacts[3] c_contacts[4] c_contacts[5] c_contacts[6] c_contacts[7] c_contacts[8] c_contacts[9] c_contacts[10] c_contacts[11] c_contacts[12]
0.0 0.005 0.0 0.0 0.005 0.003 1 54 0 0.0 0.0 -2.0
0.0 0.001 0.0 0.003 0.009 0.0 2 286 0 0.5 0.0 0.0
"""


def test_parse_gives_positions_ids_and_forces():
    frame = parse_local_dump(DUMP)
    assert frame.step == 22000 and len(frame) == 2
    np.testing.assert_array_equal(frame.id_i, [1, 2])
    np.testing.assert_array_equal(frame.id_j, [54, 286])
    np.testing.assert_array_equal(frame.branch[0], [0.0, 0.0, 0.003])
    # force on i (below) by j (above) pointing down: compression of 2 N
    assert frame.normal_force[0] == pytest.approx(2.0, rel=1e-15)


def test_force_chain_slice_and_cap():
    segments = force_chain_segments(parse_local_dump(DUMP), slice_centre_y=0.005, slice_thickness=0.006, cap=1.5)
    assert len(segments.normal_force) == 1  # the second contact spans y = 0.001..0.009
    assert segments.normal_force[0] == 1.5


def test_all_force_chains_keep_every_contact_and_its_compressive_force():
    frame = parse_local_dump(DUMP)
    segments = all_force_chains(frame)
    # the first contact is in compression (2 N), the second pulls (its force counts 0), neither capped
    np.testing.assert_allclose(segments.normal_force, [2.0, 0.0], rtol=1e-15)
    np.testing.assert_array_equal(segments.start, frame.position_i)
    assert segments.cap == float("inf")


def test_truncated_dump_names_the_file(tmp_path):
    path = tmp_path / "contacts_22000.txt"
    path.write_text(DUMP.rsplit("\n", 2)[0] + "\n")
    with pytest.raises(ContactDumpError, match=rf"{path}: the NUMBER OF ENTRIES of line 4 differs from the 1 line "
                                               r"after 'ITEM: ENTRIES' \(line \d+\)$"):
        read_contacts(path)


def test_garbled_number_names_the_file():
    with pytest.raises(ContactDumpError, match=r"^x\.txt: line 11, column 11 is not a number$"):
        parse_local_dump(DUMP.replace("0.5 0.0 0.0", "0.5 0.0.1 0.0"), "x.txt")
