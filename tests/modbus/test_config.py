"""Commissioning over the bus, through pymodbus: the staged and active views, the
unlock and wrong codes, a commit and a refused one with its reason, a scene that is
not one, the commissioning tool, a reset of the statistics, and last a burst of wrong
codes that locks the node out.

Run after test_node.py (whose first test must see the node untouched). The
environment adds MODBUS_UNLOCK_CODE (the node's code, the library's default) and
MODBUS_WRONG_CODES_MAX.
"""

import os
import struct
import subprocess
import sys
import time

from conftest import UNIT, read_table, register_map, words

ILLEGAL_FUNCTION, ILLEGAL_DATA_VALUE = 1, 3


def code():
    return int(os.environ["MODBUS_UNLOCK_CODE"])


def holding():
    return {r["name"]: r for r in register_map() if r["table"] == "holding"}


def get(client, name):
    r = holding()[name]
    values = read_table(client, "holding", r["address"], words(r))
    return values[0] << 16 | values[1] if len(values) == 2 else values[0]


def write(client, name, value):
    """Writes a holding value (u16 or two registers, high word first); the answer."""
    r = holding()[name]
    if words(r) == 2:
        return client.write_registers(r["address"], [value >> 16, value & 0xFFFF], device_id=UNIT)
    return client.write_register(r["address"], value, device_id=UNIT)


def refused(answer, code):
    assert answer.isError(), answer
    assert answer.exception_code == code, answer


def f32(x):
    return struct.unpack(">I", struct.pack(">f", x))[0]


def view(client, prefix):
    start = holding()[f"{prefix}_thresholds_on"]["address"]
    return read_table(client, "holding", start, 64)


def test_staged_and_active_views_agree_and_writes_need_the_code(client):
    assert view(client, "config") == view(client, "active")
    assert get(client, "config_source") == 0
    assert get(client, "unlock") == 0
    before = get(client, "refused_writes")
    refused(write(client, "config_warning", f32(0.7)), ILLEGAL_FUNCTION)
    refused(write(client, "command", 1), ILLEGAL_FUNCTION)
    assert get(client, "refused_writes") == before + 2
    assert get(client, "staged") == 0


def coil_address(name):
    return next(r["address"] for r in register_map() if r["table"] == "coil" and r["name"] == name)


def test_latching_and_the_sample_source_need_the_code_acknowledging_does_not(client):
    latching = get(client, "latching")
    external = get(client, "external_mode")
    before = get(client, "refused_writes")
    refused(write(client, "latching", latching ^ 1), ILLEGAL_FUNCTION)
    refused(write(client, "external_mode", external ^ 1), ILLEGAL_FUNCTION)
    refused(client.write_coil(coil_address("latch_alarm"), True, device_id=UNIT), ILLEGAL_FUNCTION)
    refused(client.write_coil(coil_address("external_samples"), not external, device_id=UNIT),
            ILLEGAL_FUNCTION)
    # Several coils in one request, an acknowledgement among them: refused whole.
    refused(client.write_coils(coil_address("acknowledge"), [True, True], device_id=UNIT),
            ILLEGAL_FUNCTION)
    assert get(client, "refused_writes") == before + 5
    assert (get(client, "latching"), get(client, "external_mode")) == (latching, external)
    # An operator's acknowledgement needs no code.
    assert not client.write_coil(coil_address("acknowledge"), True, device_id=UNIT).isError()
    assert not write(client, "acknowledge_alarms", 15).isError()
    # After the unlock the switches are taken; put back, then locked again.
    assert not write(client, "unlock", code()).isError()
    assert not client.write_coil(coil_address("latch_alarm"), True, device_id=UNIT).isError()
    assert get(client, "latching") == latching | 2
    assert not write(client, "latching", latching).isError()
    assert get(client, "latching") == latching
    assert not write(client, "command", 3).isError()
    assert get(client, "unlock") == 0


def test_a_wrong_code_is_refused_and_counted(client):
    before = get(client, "unlock_failures")
    refused(write(client, "unlock", (code() + 1) & 0xFFFF), ILLEGAL_DATA_VALUE)
    assert get(client, "unlock_failures") == before + 1
    assert not write(client, "unlock", code()).isError()
    assert get(client, "unlock") > 0


def test_a_commit_applies_the_staged_copy(client):
    assert not write(client, "unlock", code()).isError()
    assert not write(client, "config_on_delay", 7000).isError()
    assert get(client, "config_on_delay") == 7000
    assert get(client, "active_on_delay") != 7000
    assert get(client, "staged") == 1
    assert not write(client, "command", 1).isError()
    assert get(client, "active_on_delay") == 7000
    assert view(client, "config") == view(client, "active")
    assert get(client, "commit_error") == 0
    assert get(client, "config_source") == 1
    assert get(client, "unlock") == 0


def test_a_refused_commit_says_why_and_changes_nothing(client):
    assert not write(client, "unlock", code()).isError()
    active = view(client, "active")
    alarm = struct.unpack(">f", struct.pack(">I", get(client, "active_alarm")))[0]
    assert not write(client, "config_warning", f32(alarm + 1.0)).isError()
    refused(write(client, "command", 1), ILLEGAL_DATA_VALUE)
    assert get(client, "commit_error") == 0x11  # the warning not before the alarm
    assert view(client, "active") == active
    assert not write(client, "command", 2).isError()  # revert
    assert view(client, "config") == active
    # Nothing staged.
    refused(write(client, "command", 1), ILLEGAL_DATA_VALUE)
    assert get(client, "commit_error") == 1
    # A switch outside its domain, at the write.
    refused(write(client, "config_thresholds_on", 2), ILLEGAL_DATA_VALUE)


def test_bytes_that_are_not_a_scene_are_refused(client):
    assert not write(client, "unlock", code()).isError()
    n = get(client, "scene_bytes")
    assert n > 0
    active_crc = get(client, "scene_active_crc")
    start = next(r["address"] for r in register_map() if r["name"] == "scene_0_word")
    assert not client.write_registers(start, [0] * ((n + 1) // 2), device_id=UNIT).isError()
    assert get(client, "staged") == 2
    refused(write(client, "command", 1), ILLEGAL_DATA_VALUE)
    assert get(client, "commit_error") == 0x21  # not a prepared scene (magic)
    assert get(client, "scene_active_crc") == active_crc
    assert not write(client, "command", 2).isError()
    assert not write(client, "command", 3).isError()  # lock
    assert get(client, "unlock") == 0


def commission(client, *args):
    """Runs tools/commission.py against the node (the pymodbus client steps aside:
    QEMU's serial socket takes one client at a time); its exit status and stderr."""
    client.close()
    time.sleep(0.1)
    done = subprocess.run(
        [sys.executable, "tools/commission.py", "--tcp", f"127.0.0.1:{os.environ['MODBUS_PORT']}",
         "--registers", os.environ["MODBUS_REGISTERS"], *args],
        capture_output=True, text=True, timeout=900)
    time.sleep(0.1)
    assert client.connect()
    return done.returncode, done.stderr + done.stdout


def test_the_commissioning_tool_writes_a_scene_the_node_was_not_built_with(client):
    scene = open(os.environ["MODBUS_SCENE"], "rb").read()
    crc = int.from_bytes(scene[-4:], "little")
    assert get(client, "scene_active_crc") != crc
    status, err = commission(client, "--code", str((code() + 1) & 0xFFFF), "--prepared", os.environ["MODBUS_SCENE"])
    assert status == 1 and "wrong code" in err, err
    status, err = commission(client, "--code", str(code()), "--set", "config_warning=2.5")
    assert status == 1 and "commit refused" in err and "0x11" in err, err
    assert get(client, "staged") == 0 and get(client, "unlock") == 0  # reverted and locked
    status, err = commission(client, "--code", str(code()), "--prepared", os.environ["MODBUS_SCENE"],
                             "--set", "config_off_delay=45000", "--set", "config_alarm=1.1")
    assert status == 0, err
    assert get(client, "scene_active_crc") == crc
    assert get(client, "active_off_delay") == 45000
    assert get(client, "active_alarm") == f32(1.1)
    assert get(client, "config_source") == 1


def plan(tmp_path, scene):
    """The planner's table for `scene` (the monitor example's --thresholds, with the
    default configuration), on the node's core."""
    table = tmp_path / "thresholds.csv"
    done = subprocess.run(
        ["cargo", "run", "--quiet", "--release", "--example", "monitor", "--", "--model",
         os.environ["MODBUS_CORE"], "--scene", str(scene), "--plot", str(tmp_path / "plan.svg"),
         "--thresholds", str(table)], capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stderr
    return table


PLANNED = "P,phi0,phi_warning,phi_warning_clear,phi_alarm,phi_alarm_clear\n"
# The thresholds the planner plans with (monitor::Config::default()).
DEFAULT_THRESHOLDS = "warning,0.8\nalarm,1.0\ndeadband,0.05\n"


def test_the_commissioning_tool_takes_what_an_engineer_planned(client, tmp_path):
    """A scene file (prepared by the tool), a configuration file and the planner's
    table in; the node runs them. A table planned for other loads, or with another
    warning than the configuration's, is refused before anything is written."""
    scene = tmp_path / "scene.csv"
    scene.write_text("R1,R2,G,nu,mu,length\n0.06,0.04,79.3e9,0.3,0.25,0.02\n")
    config = tmp_path / "config.csv"
    config.write_text("name,value\n# on-delay and the planner's thresholds\nconfig_on_delay,6000\n"
                      + DEFAULT_THRESHOLDS)
    table = plan(tmp_path, scene)
    wide = tmp_path / "wide.csv"
    wide.write_text(PLANNED + "500,0.0006,0.0004,0.00038,0.0005,0.00048\n90000,0.0007,,,,\n")
    crc = get(client, "scene_active_crc")
    core = os.environ["MODBUS_CORE"]
    status, err = commission(client, "--code", str(code()), "--scene", str(scene), "--core", core,
                             "--config", str(config), "--thresholds", str(wide))
    assert status == 1 and "planned with another configuration" in err, err
    assert get(client, "staged") == 0 and get(client, "active_on_delay") != 6000
    # The table says the warning is raised at d/b 0.8; the configuration says 0.75.
    status, err = commission(client, "--code", str(code()), "--scene", str(scene), "--core", core,
                             "--config", str(config), "--set", "warning=0.75",
                             "--thresholds", str(table))
    assert status == 1 and "planned with another configuration" in err, err
    assert "config_warning is 0.75" in err and "Traceback" not in err, err
    assert get(client, "staged") == 0 and get(client, "unlock") == 0
    assert get(client, "active_on_delay") != 6000
    # A table for another scene (the critical angles differ).
    other = tmp_path / "other"
    other.mkdir()
    other_scene = other / "scene.csv"
    other_scene.write_text("R1,R2,G,nu,mu\n0.05,0.05,79.3e9,0.3,0.3\n")
    status, err = commission(client, "--code", str(code()), "--scene", str(scene), "--core", core,
                             "--config", str(config), "--thresholds", str(plan(other, other_scene)))
    assert status == 1 and "planned for another scene" in err, err
    events = tmp_path / "events.csv"
    refusals = get(client, "refused_writes")
    status, out = commission(client, "--code", str(code()), "--scene", str(scene), "--core", core,
                             "--config", str(config), "--thresholds", str(table),
                             "--events", str(events))
    assert status == 0, out
    assert get(client, "refused_writes") == refusals, "the tool wrote nothing the node refused"
    assert "thresholds planned for " in out and "events held" in out, out
    assert get(client, "active_on_delay") == 6000
    assert get(client, "active_warning") == f32(0.8)
    assert get(client, "scene_active_crc") not in (0, crc)
    held = events.read_text().splitlines()
    assert held[0] == "t,seq,state,from,kind,fault,P,phi,s,F,phi0,margin,time_to_critical,time_ms"
    assert len(held) - 1 == int(out.split(" events held")[0].split()[-1]) > 0, out


def test_the_commissioning_tool_runs_from_any_folder(client, tmp_path):
    """The register map and the examples are found beside the tool, not in the
    working folder."""
    client.close()
    time.sleep(0.1)
    done = subprocess.run(
        [sys.executable, os.path.abspath("tools/commission.py"), "--tcp",
         f"127.0.0.1:{os.environ['MODBUS_PORT']}"],
        capture_output=True, text=True, timeout=120, cwd=tmp_path)
    time.sleep(0.1)
    assert client.connect()
    assert done.returncode == 0, done.stderr
    assert "config_source" in done.stdout and "Traceback" not in done.stderr, done.stderr


def untouched(client):
    """What a refused run must leave as it was."""
    return {n: get(client, n) for n in ("latching", "staged", "unlock", "config_on_delay",
                                        "active_on_delay", "config_spike_window", "unlock_failures",
                                        "refused_writes", "staged_generation", "config_source")}


def test_a_value_outside_its_register_is_refused_before_anything_is_written(client, tmp_path):
    """Each value checked against its register's type and domain (the map's min and
    max): refused with a message naming it, the node not even unlocked; a bad value
    after a good one in a configuration file leaves the node as it was."""
    before = untouched(client)
    config = tmp_path / "config.csv"
    config.write_text("name,value\nlatching,15\nconfig_on_delay,5000.5\n")
    cases = [
        (["--config", str(config)], "config_on_delay = 5000.5"),
        (["--set", "config_on_delay=-1"], "config_on_delay = -1"),
        (["--set", "config_spike_window=65541"], "config_spike_window = 65541"),
        (["--set", "new_code=70000"], "new_code = 70000"),
        (["--set", "config_warning=nan"], "config_warning = nan"),
        (["--set", "config_deadband=-0.1"], "config_deadband = -0.1"),
        (["--set", "active_on_delay=5"], "active_on_delay is read only"),
    ]
    for args, named in cases:
        status, err = commission(client, "--code", str(code()), *args)
        assert status == 1 and named in err and "Traceback" not in err, (args, err)
    for bad in ("70000", "-1", "12a"):
        status, err = commission(client, "--code", bad, "--set", "config_on_delay=6000")
        assert status == 1 and f"--code {bad}" in err and "Traceback" not in err, err
    assert untouched(client) == before


def test_any_failure_after_the_unlock_puts_the_node_back(client):
    """Whatever fails once the node is unlocked (here the line, while the third value
    is written): the switch put back, the staged copy reverted, the node locked, and
    the failure goes on up."""
    sys.path.insert(0, os.path.abspath("tools"))
    import commission as tool
    regs = tool.Map(os.environ["MODBUS_REGISTERS"])
    before = untouched(client)
    settings = tool.settings_words(regs, [("latching", str(before["latching"] ^ 15)),
                                          ("config_on_delay", "7777"), ("config_warning", "0.71")])

    class LineDrops(tool.Node):
        def write(self, name, words):
            if name == "config_warning":
                raise ConnectionError("the line dropped")
            return super().write(name, words)

    node = LineDrops(client, regs, UNIT)
    try:
        tool.commission(node, code(), settings, None)
        raise AssertionError("the failure was swallowed")
    except ConnectionError:
        pass
    after = untouched(client)
    for name in ("latching", "staged", "unlock", "config_on_delay", "active_on_delay"):
        assert after[name] == before[name], (name, before, after)


def test_a_switch_alone_is_written_without_a_commit(client):
    """`--set latching=N` alone: applied and kept, nothing to commit, the node locked."""
    latching = get(client, "latching")
    refusals = get(client, "refused_writes")
    status, out = commission(client, "--code", str(code()), "--set", f"latching={latching ^ 5}")
    assert status == 0 and "switched: latching" in out, out
    assert get(client, "refused_writes") == refusals
    assert get(client, "latching") == latching ^ 5 and get(client, "unlock") == 0
    assert get(client, "config_source") == 1
    status, out = commission(client, "--code", str(code()), "--set", f"latching={latching}")
    assert status == 0, out
    assert get(client, "latching") == latching


def samples_counted(client):
    r = next(r for r in register_map() if r["table"] == "input" and r["name"] == "samples")
    w = read_table(client, "input", r["address"], 2)
    return w[0] << 16 | w[1]


def test_the_commissioning_tool_resets_the_statistics(client):
    """Command 4 changes state: refused while locked; through the tool after the
    unlock, the statistics start afresh and the node is locked again."""
    counted = samples_counted(client)
    assert counted > 0
    refused(write(client, "command", 4), ILLEGAL_FUNCTION)
    assert samples_counted(client) == counted
    # A run refused (a value outside its domain; a commit refused, the warning after
    # the alarm) resets nothing.
    for value in ("nan", "2.5"):
        status, err = commission(client, "--code", str(code()), "--reset-statistics",
                                 "--set", f"config_warning={value}")
        assert status == 1 and ("config_warning" in err or "commit refused" in err), err
        assert samples_counted(client) == counted, value
        assert get(client, "unlock") == 0 and get(client, "staged") == 0
    refusals = get(client, "refused_writes")
    status, out = commission(client, "--code", str(code()), "--reset-statistics",
                             "--set", "config_on_delay=6500")
    assert status == 0 and "statistics reset" in out, out
    assert samples_counted(client) == 0 and get(client, "active_on_delay") == 6500
    assert get(client, "unlock") == 0 and get(client, "refused_writes") == refusals


# Last: the lock-out lasts minutes of the node's time.
def test_a_burst_of_wrong_codes_locks_out(client):
    wrong = (code() + 1) & 0xFFFF
    lockouts_before = get(client, "lockout")
    assert lockouts_before == 0
    for _ in range(int(os.environ["MODBUS_WRONG_CODES_MAX"])):
        refused(write(client, "unlock", wrong), ILLEGAL_DATA_VALUE)
    assert get(client, "lockout") > 0
    refused(write(client, "unlock", code()), ILLEGAL_FUNCTION)
    refused(write(client, "config_warning", f32(0.5)), ILLEGAL_FUNCTION)
    assert get(client, "unlock") == 0
