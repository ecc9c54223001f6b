"""trace.mcap opened with Rerun's own MCAP reader (``rerun.chunk.McapReader``, the reader of
``rerun mcap convert``): it reads the whole file and sees every topic mobigrasp wrote, with
its schema and its message count. Needs the ``rerun`` extra, which ``make test-all`` installs
(docs/outputs.md "trace.mcap in Rerun")."""

import pytest
from mcap.reader import make_reader

# a slow test: `make test-all` installs the extra; where it is missing the test fails, saying so
pytestmark = pytest.mark.slow


def _reader():
    try:
        from rerun import chunk
    except ImportError:
        pytest.fail("Rerun's MCAP reader is missing: pip install -e '.[rerun]' (make test-all)")
    return chunk


def _ours(path):
    """{topic: (schema name, message count)} as the mcap library reads the file."""
    with open(path, "rb") as fh:
        summary = make_reader(fh).get_summary()
    counts = summary.statistics.channel_message_counts
    return {ch.topic: (summary.schemas[ch.schema_id].name, counts[ch.id])
            for ch in summary.channels.values()}


def test_rerun_reads_every_topic_of_a_run(short_runs):
    path = short_runs["paper001-sim1"] / "trace.mcap"
    reader = _reader().McapReader(path)
    info = reader.info()
    seen = {ch.topic: (ch.schema.name if ch.schema else None, ch.message_count)
            for ch in info.channels}
    assert info.library == "mobigrasp" and info.metadata_count == 1
    assert seen == _ours(path)
    # the run's robot, camera and telemetry are among them
    for topic in ("/scene", "/tf", "/camera/image", "/camera/calibration", "/joints",
                  "/mcu/encoders", "/mcu/sonars"):
        assert seen[topic][1] > 0, topic
    # decoded into Rerun's store: one entity per topic, each message a row on the log time
    store = reader.stream().collect()
    entities = set(store.schema().entity_paths())
    assert set(seen) <= entities
    rows = {}
    for line in store.summary().splitlines():
        entity, *fields = line.split()
        if "static=False" in fields:
            rows[entity] = rows.get(entity, 0) + int(fields[0].removeprefix("rows="))
    assert {t: rows.get(t) for t in seen} == {t: n for t, (_, n) in seen.items()}
