#!/usr/bin/python3
"""slurm_test.py: `prsm serve --executor slurm` against stand-ins of Slurm's commands (issue 20,
docs/mpi.md "The service on a cluster").

    /usr/bin/python3 tests/slurm_test.py PRSM SOURCE_DIR

sbatch, squeue, sacct and scancel are shell scripts on PATH that keep each job's state in files:
sbatch records the call, prints a job id and runs the job script in the background (after a
moment PENDING, or held while a hold file exists), squeue lists the job while it is PENDING or
RUNNING, sacct gives its final state, scancel kills it. So the service's submission, polling
and result-storing path runs for real, with `prsm run-job` doing the work, and the results are
compared with a service that runs the same requests in its own workers:

  * a study above --slurm-min-samples goes to Slurm (one sbatch, with the --sbatch-arg given) and
    its result document and samples CSV are the local service's (timings and ids masked); a
    study below it runs locally (no sbatch); the same request again is a cache hit (no sbatch);
  * an allocation above the size goes to Slurm too, with the local result;
  * a study whose failure policy aborts fails on Slurm with the local run's problem document;
  * a job cancelled while Slurm holds it is scancel'ed and ends cancelled;
  * a service stopped (SIGTERM) while Slurm holds a job leaves that job running, and the
    restarted service picks it up (no second sbatch, no scancel) with the local result; a service
    killed (SIGKILL) while its job was held, which then finished, reads the result back at the
    restart.
"""
import json
import os
import socket
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request

prsm, src = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])

FAKE = {
    "sbatch": r'''#!/bin/bash
# stand-in of sbatch: --parsable, --job-name=, --chdir=, --output=, other options, the script
set -eu
d=$FAKE_SLURM
out=/dev/null; dir=.; args=()
for a in "$@"; do
  case "$a" in
    --output=*) out=${a#--output=} ;;
    --chdir=*) dir=${a#--chdir=} ;;
  esac
  args+=("$a")
done
script=${args[-1]}
[ -f "$script" ] || { echo "sbatch: error: Unable to open file $script" >&2; exit 1; }
id=$(( $(cat "$d/next" 2>/dev/null || echo 1000) + 1 ))
echo "$id" > "$d/next"
echo "sbatch $*" >> "$d/calls.log"
echo PENDING > "$d/$id.state"
setsid bash -c '
  d=$1; id=$2; dir=$3; out=$4; script=$5
  sleep 0.3
  while [ -e "$d/hold" ]; do sleep 0.1; done
  [ "$(cat "$d/$id.state")" = PENDING ] || exit 0
  echo RUNNING > "$d/$id.state"
  cd "$dir" && bash "$script" > "$out" 2>&1 && s=COMPLETED || s=FAILED
  [ "$(cat "$d/$id.state")" = RUNNING ] && echo $s > "$d/$id.state"
' _ "$d" "$id" "$dir" "$out" "$script" < /dev/null > /dev/null 2>&1 &
echo $! > "$d/$id.pid"
echo "$id;fakecluster"
''',
    "squeue": r'''#!/bin/bash
# stand-in of squeue -h -j ID -o %T
d=$FAKE_SLURM; id=$3
echo "squeue $*" >> "$d/calls.log"
s=$(cat "$d/$id.state" 2>/dev/null || echo gone)
case "$s" in
  PENDING|RUNNING) echo "$s" ;;
  *) echo "slurm_load_jobs error: Invalid job id specified" >&2; exit 1 ;;
esac
''',
    "sacct": r'''#!/bin/bash
# stand-in of sacct -n -P -X -j ID -o State
d=$FAKE_SLURM; id=$5
echo "sacct $*" >> "$d/calls.log"
cat "$d/$id.state"
''',
    "scancel": r'''#!/bin/bash
# stand-in of scancel ID
d=$FAKE_SLURM; id=$1
echo "scancel $*" >> "$d/calls.log"
echo "CANCELLED by 0" > "$d/$id.state"
kill -- -"$(cat "$d/$id.pid")" 2>/dev/null || true
''',
}


def fail(msg):
    print("slurm: FAIL: " + msg, file=sys.stderr)
    sys.exit(1)


def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def call(port, method, path, body=None):
    data = json.dumps(body).encode() if body is not None else None
    req = urllib.request.Request("http://127.0.0.1:%d%s" % (port, path), data=data, method=method,
                                 headers={"Content-Type": "application/json"} if data else {})
    try:
        with urllib.request.urlopen(req, timeout=30) as r:
            return r.status, r.read().decode()
    except urllib.error.HTTPError as e:
        return e.code, e.read().decode()


def start(tmp, name, args, env, log_name=None):
    port = free_port()
    log = open(os.path.join(tmp, (log_name or name) + ".log"), "w")
    p = subprocess.Popen([prsm, "serve", "--port", str(port), "--db", os.path.join(tmp, name + ".db"),
                          "--data-dir", src] + args, stdout=log, stderr=subprocess.STDOUT, env=env, cwd=tmp)
    deadline = time.time() + 20
    while time.time() < deadline:
        if p.poll() is not None:
            fail("%s service exited: %s" % (name, open(log.name).read()))
        try:
            socket.create_connection(("127.0.0.1", port), timeout=1).close()
            return p, port
        except OSError:
            time.sleep(0.05)
    fail("%s service did not start" % name)


def submit(port, collection, doc):
    st, text = call(port, "POST", "/v1/" + collection, doc)
    if st not in (200, 201, 202):
        fail("POST /v1/%s: %d %s" % (collection, st, text))
    return json.loads(text)


def wait(port, collection, job_id, states=("done", "failed", "cancelled"), timeout=120):
    deadline = time.time() + timeout
    while time.time() < deadline:
        st, text = call(port, "GET", "/v1/%s/%s" % (collection, job_id))
        j = json.loads(text)
        if j.get("state") in states:
            return j
        time.sleep(0.1)
    fail("job %s did not reach %s" % (job_id, states))


MASK = {"timing_s", "build", "elapsed_s", "job_id", "id", "created_at", "started_at", "finished_at",
        "cache_hit", "links", "self", "href", "eta_s"}


def masked(v):
    if isinstance(v, dict):
        return {k: ("MASKED" if k in MASK else masked(x)) for k, x in v.items()}
    if isinstance(v, list):
        return [masked(x) for x in v]
    return v


def calls(fake):
    try:
        return open(os.path.join(fake, "calls.log")).read().splitlines()
    except FileNotFoundError:
        return []


def main():
    with tempfile.TemporaryDirectory() as tmp:
        fake = os.path.join(tmp, "fake-slurm")
        bindir = os.path.join(tmp, "bin")
        os.makedirs(fake)
        os.makedirs(bindir)
        for name, text in FAKE.items():
            path = os.path.join(bindir, name)
            with open(path, "w") as f:
                f.write(text)
            os.chmod(path, 0o755)
        env = dict(os.environ, FAKE_SLURM=fake, PATH=bindir + ":" + os.environ.get("PATH", ""))
        slurm_args = ["--executor", "slurm", "--slurm-min-samples", "1000", "--slurm-spool", "spool",
                      "--slurm-poll-s", "0.1", "--sbatch-arg", "--partition=test"]
        slurm, sport = start(tmp, "slurm", slurm_args, env)
        slurm_log = "slurm"
        local, lport = start(tmp, "local", [], dict(os.environ))
        try:
            base = json.load(open(os.path.join(src, "studies/case-a-tolerances.json")))
            big = json.loads(json.dumps(base))
            big["monte_carlo"].update(samples=2048, block_size=256, targets=[])
            small = json.loads(json.dumps(big))
            small["monte_carlo"].update(samples=256)

            # a study above the size: on Slurm, the local service's result and CSV
            j = submit(sport, "studies", big)
            done = wait(sport, "studies", j["id"])
            if done["state"] != "done":
                fail("the Slurm study ended %s: %s" % (done["state"], json.dumps(done)[:800]))
            sb = [c for c in calls(fake) if c.startswith("sbatch")]
            if len(sb) != 1 or "--partition=test" not in sb[0] or "--parsable" not in sb[0]:
                fail("expected one sbatch with --parsable and --partition=test, got %s" % sb)
            if not any(c.startswith("squeue") for c in calls(fake)):
                fail("the service never polled squeue")
            lj = submit(lport, "studies", big)
            ldone = wait(lport, "studies", lj["id"])
            if masked(done["result"]) != masked(ldone["result"]):
                fail("the Slurm study's result differs from the local one")
            if done.get("progress", {}).get("samples_done") != ldone.get("progress", {}).get("samples_done"):
                fail("the Slurm study's counts differ: %s / %s" % (done.get("progress"), ldone.get("progress")))
            _, csv_s = call(sport, "GET", "/v1/studies/%s/samples.csv" % j["id"])
            _, csv_l = call(lport, "GET", "/v1/studies/%s/samples.csv" % lj["id"])
            if csv_s != csv_l or len(csv_s) < 1000:
                fail("the Slurm study's samples CSV differs from the local one")
            print("slurm: a study above the size ran through sbatch/squeue/sacct, result and CSV as the local service's")

            # the same request again: the cache; a small study: locally
            again = submit(sport, "studies", big)
            if not again.get("result") and wait(sport, "studies", again["id"])["state"] != "done":
                fail("the repeated study was not answered")
            sj = submit(sport, "studies", small)
            if wait(sport, "studies", sj["id"])["state"] != "done":
                fail("the small study failed")
            if len([c for c in calls(fake) if c.startswith("sbatch")]) != 1:
                fail("a cached or small study went to Slurm: %s" % calls(fake))
            print("slurm: the repeated study came from the cache and the small one ran locally (no sbatch)")

            # an allocation above the size
            al = json.load(open(os.path.join(src, "studies/allocate-case-a.json")))
            al["monte_carlo"].update(samples=2048, max_corrections=3)
            al["study"]["monte_carlo"].update(block_size=256)
            aj = submit(sport, "allocations", al)
            adone = wait(sport, "allocations", aj["id"])
            laj = submit(lport, "allocations", al)
            ladone = wait(lport, "allocations", laj["id"])
            if adone["state"] != "done" or masked(adone["result"]) != masked(ladone["result"]):
                fail("the Slurm allocation (%s) differs from the local one" % adone["state"])
            if len([c for c in calls(fake) if c.startswith("sbatch")]) != 2:
                fail("the allocation did not go to Slurm")
            print("slurm: an allocation ran on Slurm with the local result")

            # a failing study: the local run's problem document
            bad = json.loads(json.dumps(big))
            for t in bad["tolerances"]:
                if t["parameter"] == "friction.screw_roller_mu":
                    t.update(lower=-0.058, mode=0.0, upper=0.03)
            bad["monte_carlo"].update(failure={"policy": "abort"})
            fj = submit(sport, "studies", bad)
            fdone = wait(sport, "studies", fj["id"])
            lfj = submit(lport, "studies", bad)
            lfdone = wait(lport, "studies", lfj["id"])
            if fdone["state"] != "failed" or lfdone["state"] != "failed":
                fail("the aborting study: %s on Slurm, %s locally" % (fdone["state"], lfdone["state"]))
            if masked(fdone.get("problem")) != masked(lfdone.get("problem")):
                fail("the failure differs: %s / %s" % (fdone.get("problem"), lfdone.get("problem")))
            print("slurm: a failing study failed on Slurm with the local problem document")

            # a cancel while Slurm holds the job
            open(os.path.join(fake, "hold"), "w").close()
            held = json.loads(json.dumps(big))
            held["monte_carlo"]["seed"] = 99
            hj = submit(sport, "studies", held)
            deadline = time.time() + 30
            while len([c for c in calls(fake) if c.startswith("sbatch")]) < 4 and time.time() < deadline:
                time.sleep(0.05)
            st, _ = call(sport, "DELETE", "/v1/studies/" + hj["id"])
            if st not in (200, 202):
                fail("DELETE of the held job: %d" % st)
            hdone = wait(sport, "studies", hj["id"])
            deadline = time.time() + 10
            while not any(c.startswith("scancel") for c in calls(fake)) and time.time() < deadline:
                time.sleep(0.05)
            os.unlink(os.path.join(fake, "hold"))
            if hdone["state"] != "cancelled" or not any(c.startswith("scancel") for c in calls(fake)):
                fail("the held job: %s, scancel %s" % (hdone["state"], [c for c in calls(fake) if c.startswith("scancel")]))
            print("slurm: a job cancelled while queued was scancel'ed")

            def n_calls(prefix):
                return len([c for c in calls(fake) if c.startswith(prefix)])

            def held_job(seed):
                open(os.path.join(fake, "hold"), "w").close()
                doc = json.loads(json.dumps(big))
                doc["monte_carlo"]["seed"] = seed
                before = n_calls("sbatch")
                job = submit(sport, "studies", doc)
                deadline = time.time() + 30
                while n_calls("sbatch") == before and time.time() < deadline:
                    time.sleep(0.05)
                # the service writes the Slurm job's id into its spool once sbatch has answered:
                # killed before that, it could only submit the job again
                jobid = os.path.join(tmp, "spool", job["id"], "jobid")
                while not os.path.exists(jobid) and time.time() < deadline:
                    time.sleep(0.05)
                if n_calls("sbatch") != before + 1 or not os.path.exists(jobid):
                    fail("the held study (seed %d) was not submitted" % seed)
                return doc, job, open(os.path.join(fake, "next")).read().strip()

            # the service stopped (SIGTERM) while Slurm holds a job: the Slurm job is left to run,
            # and the restarted service picks it up (no second sbatch, no scancel)
            doc, rj, slurm_id = held_job(7)
            sbatches, scancels = n_calls("sbatch"), n_calls("scancel")
            slurm.terminate()
            if slurm.wait(timeout=20) != 0:
                fail("the service stopped with a Slurm job held exited non-zero: %s" %
                     open(os.path.join(tmp, slurm_log + ".log")).read()[-2000:])
            if n_calls("scancel") != scancels:
                fail("stopping the service cancelled its Slurm job: %s" % calls(fake)[-3:])
            slurm_log = "slurm-restart-1"
            slurm, sport = start(tmp, "slurm", slurm_args, env, slurm_log)
            os.unlink(os.path.join(fake, "hold"))
            rdone = wait(sport, "studies", rj["id"])
            lr = submit(lport, "studies", doc)
            lrdone = wait(lport, "studies", lr["id"])
            if rdone["state"] != "done" or masked(rdone["result"]) != masked(lrdone["result"]):
                fail("the job picked up after a restart: %s, or its result differs from the local one" % rdone["state"])
            if n_calls("sbatch") != sbatches:
                fail("the restarted service submitted the job again: %s" % [c for c in calls(fake) if c.startswith("sbatch")])
            print("slurm: a service stopped with Slurm job %s queued left it running and picked it up at the restart" %
                  slurm_id)

            # the service killed (SIGKILL) while Slurm holds a job, which then finishes while the
            # service is down: the restart reads its result without a second sbatch
            doc, kj, slurm_id = held_job(8)
            sbatches = n_calls("sbatch")
            slurm.kill()
            slurm.wait(timeout=20)
            os.unlink(os.path.join(fake, "hold"))
            deadline = time.time() + 60
            while time.time() < deadline and open(os.path.join(fake, slurm_id + ".state")).read().strip() != "COMPLETED":
                time.sleep(0.1)
            slurm_log = "slurm-restart-2"
            slurm, sport = start(tmp, "slurm", slurm_args, env, slurm_log)
            kdone = wait(sport, "studies", kj["id"])
            if kdone["state"] != "done" or kdone.get("progress", {}).get("samples_done") != 2048:
                fail("the job finished while the service was down: %s %s" % (kdone["state"], kdone.get("progress")))
            if n_calls("sbatch") != sbatches:
                fail("the restarted service submitted the finished job again")
            print("slurm: a Slurm job that finished while the service was down was read back at the restart")
        finally:
            codes = []
            for p in (slurm, local):
                p.terminate()
                try:
                    codes.append(p.wait(timeout=20))
                except subprocess.TimeoutExpired:
                    p.kill()
                    codes.append("killed")
        # a service stopped by SIGTERM exits 0 (under a sanitizer: nothing to report)
        for name, code in zip((slurm_log, "local"), codes):
            if code != 0:
                fail("the %s service exited %s: %s" % (name, code, open(os.path.join(tmp, name + ".log")).read()[-3000:]))
    print("slurm: ok")


main()
