#!/usr/bin/python3
"""Writes the small ROS bag seeds of the fuzz targets (seed.db3, seed.mcap, seed.bag) from
the real bags in ../shared/data/real: a few of their messages, payloads cut to 600 bytes,
in each container (MCAP: one plain chunk and a summary with Statistics; ROS 1: a bz2
chunk and an uncompressed one, with the index). Run from the repository root."""
import bz2, os, sqlite3, struct, sys

real = os.path.join(os.path.dirname(__file__), "../../../shared/data/real")
out = os.path.dirname(os.path.abspath(__file__))

def cdr_packet_cut(d, keep=600):
    """A CDR EventPacket with its events cut to `keep` bytes (whole words/events)."""
    o = 4
    sl = struct.unpack_from('<I', d, o + 8)[0]
    o2 = o + 12 + sl
    o2 = (o2 - 4 + 3) // 4 * 4 + 4
    o3 = (o2 + 8 - 4 + 7) // 8 * 8 + 4
    el = struct.unpack_from('<I', d, o3 + 16)[0]
    o4 = o3 + 20 + el + 1
    o4 = (o4 - 4 + 3) // 4 * 4 + 4
    n = struct.unpack_from('<I', d, o4)[0]
    keep = min(n, keep)
    return d[:o4] + struct.pack('<I', keep) + d[o4 + 4:o4 + 4 + keep]

def db3_messages(path, k):
    c = sqlite3.connect('file:' + path + '?mode=ro', uri=True)
    return [bytes(r[0]) for r in c.execute('select data from messages order by id limit ?', (k,))]

# rosbag2 (SQLite): an evt3 topic and a libcaer topic.
evt3 = [cdr_packet_cut(m) for m in db3_messages(real + "/ros2-event-camera-py/test_events_1/test_events_1.db3", 3)]
caer = [cdr_packet_cut(m, 400) for m in db3_messages(real + "/ros2-event-camera-codecs/test_data_libcaer_rollover/libcaer_rollover_0.db3", 2)]
p = os.path.join(out, "seed.db3")
if os.path.exists(p): os.remove(p)
db = sqlite3.connect(p)
db.execute("PRAGMA page_size=1024")
db.executescript("""CREATE TABLE topics(id INTEGER PRIMARY KEY,name TEXT NOT NULL,type TEXT NOT NULL,serialization_format TEXT NOT NULL,offered_qos_profiles TEXT NOT NULL);
CREATE TABLE messages(id INTEGER PRIMARY KEY,topic_id INTEGER NOT NULL,timestamp INTEGER NOT NULL, data BLOB NOT NULL);""")
db.execute("INSERT INTO topics VALUES(1,'/event_camera/events','event_camera_msgs/msg/EventPacket','cdr','')")
db.execute("INSERT INTO topics VALUES(2,'/caer/events','event_camera_msgs/msg/EventPacket','cdr','')")
for i, m in enumerate(evt3): db.execute("INSERT INTO messages(topic_id,timestamp,data) VALUES(1,?,?)", (i, m))
for i, m in enumerate(caer): db.execute("INSERT INTO messages(topic_id,timestamp,data) VALUES(2,?,?)", (i, m))
db.commit(); db.close()

# MCAP: libcaer_cmp messages from the real MCAP's first chunk.
d = open(real + "/ros2-event-camera-py/test_events_2/test_events_2_0.mcap", 'rb').read()
def records(buf, o, end):
    while o + 9 <= end:
        op = buf[o]; ln = struct.unpack_from('<Q', buf, o + 1)[0]
        yield op, buf[o + 9:o + 9 + ln]
        o += 9 + ln
def rec(op, c): return bytes([op]) + struct.pack('<Q', len(c)) + c
schema = channel = None; msgs = []
for op, c in records(d, 8, len(d) - 8):
    if op == 3 and schema is None: schema = c
    if op == 4 and channel is None: channel = c
    if op == 6 and not msgs:
        cl = struct.unpack_from('<I', c, 28)[0]
        body = c[32 + cl + 8:]
        for iop, ic in records(body, 0, len(body)):
            if iop == 5 and len(msgs) < 3: msgs.append(ic[:22] + cdr_packet_cut(ic[22:], 500))
schema = schema[:2] + schema[2:6] + schema[6:6 + struct.unpack_from('<I', schema, 2)[0]]  # id, name
sname = schema[6:]
schema = schema[:2] + struct.pack('<I', len(sname)) + sname + struct.pack('<I', 7) + b'ros2msg' + struct.pack('<I', 0)
inner = rec(3, schema) + rec(4, channel) + b''.join(rec(5, m) for m in msgs)
chunk = struct.pack('<QQQI', 0, 0, len(inner), 0) + struct.pack('<I', 0) + struct.pack('<Q', len(inner)) + inner
f = b'\x89MCAP0\r\n' + rec(1, struct.pack('<I', 4) + b'ros2' + struct.pack('<I', 4) + b'seed')
f += rec(6, chunk) + rec(15, struct.pack('<I', 0))
summary_start = len(f)
counts = struct.pack('<HQ', struct.unpack_from('<H', channel, 0)[0], len(msgs))
stats = struct.pack('<QHIIIIQQ', len(msgs), 1, 1, 0, 0, 1, 0, 0) + struct.pack('<I', len(counts)) + counts
f += rec(3, schema) + rec(4, channel) + rec(11, stats)
f += rec(2, struct.pack('<QQI', summary_start, 0, 0)) + b'\x89MCAP0\r\n'
open(os.path.join(out, "seed.mcap"), 'wb').write(f)

# ROS 1: the first messages of the real bag, cut, in a bz2 chunk and a plain one, indexed.
d = open(real + "/ros2-event-camera-py/ros1/test_events_1.bag", 'rb').read()
def fields(h):
    r = {}; o = 0
    while o < len(h):
        n = struct.unpack_from('<I', h, o)[0]; k, v = h[o + 4:o + 4 + n].split(b'=', 1); r[k] = v; o += 4 + n
    return r
def ros1_records(buf, o, end):
    while o + 4 <= end:
        hl = struct.unpack_from('<I', buf, o)[0]; h = buf[o + 4:o + 4 + hl]
        dl = struct.unpack_from('<I', buf, o + 4 + hl)[0]; data = buf[o + 8 + hl:o + 8 + hl + dl]
        yield fields(h), h, data
        o += 8 + hl + dl
conn = None; ros1_msgs = []
for f_, h, data in ros1_records(d, 13, len(d)):
    if f_[b'op'] == b'\x05':
        inner = data if f_[b'compression'] == b'none' else None
        for g, ih, idata in ros1_records(inner, 0, len(inner)):
            if g[b'op'] == b'\x07' and conn is None: conn = (ih, idata)
            if g[b'op'] == b'\x02' and len(ros1_msgs) < 4:
                # ROS 1 EventPacket: header(seq, stamp, frame_id), h, w, seq, time_base, encoding, is_bigendian, events
                fl = struct.unpack_from('<I', idata, 12)[0]; o = 16 + fl + 8 + 16
                el = struct.unpack_from('<I', idata, o)[0]; o += 4 + el + 1
                n = min(struct.unpack_from('<I', idata, o)[0], 500)
                ros1_msgs.append((ih, idata[:o] + struct.pack('<I', n) + idata[o + 4:o + 4 + n]))
        break
def fld(k, v): return struct.pack('<I', len(k) + 1 + len(v)) + k + b'=' + v
def r1(h, data): return struct.pack('<I', len(h)) + h + struct.pack('<I', len(data)) + data
conn_rec = r1(*conn)
inner1 = conn_rec + b''.join(r1(h, m) for h, m in ros1_msgs[:2])
inner2 = b''.join(r1(h, m) for h, m in ros1_msgs[2:])
c1 = r1(fld(b'op', b'\x05') + fld(b'compression', b'bz2') + fld(b'size', struct.pack('<I', len(inner1))), bz2.compress(inner1))
c2 = r1(fld(b'op', b'\x05') + fld(b'compression', b'none') + fld(b'size', struct.pack('<I', len(inner2))), inner2)
def header(ix): return r1(fld(b'op', b'\x03') + fld(b'index_pos', struct.pack('<Q', ix)) + fld(b'conn_count', struct.pack('<I', 1)) + fld(b'chunk_count', struct.pack('<I', 2)), b' ' * 64)
start = 13 + len(header(0))
cid = fields(conn[0])[b'conn']
def info(pos, n): return r1(fld(b'op', b'\x06') + fld(b'ver', struct.pack('<I', 1)) + fld(b'chunk_pos', struct.pack('<Q', pos)) + fld(b'start_time', bytes(8)) + fld(b'end_time', bytes(8)) + fld(b'count', struct.pack('<I', 1)), cid + struct.pack('<I', n))
f = b'#ROSBAG V2.0\n' + header(start + len(c1) + len(c2)) + c1 + c2 + conn_rec + info(start, 2) + info(start + len(c1), 2)
open(os.path.join(out, "seed.bag"), 'wb').write(f)
print("seeds:", [(n, os.path.getsize(os.path.join(out, n))) for n in ("seed.db3", "seed.mcap", "seed.bag")])
