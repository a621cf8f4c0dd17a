#!/usr/bin/env python3
"""Build one stance library with Apache Spark as the distributed engine.

Each of the N shards of the build (``stancelib build ... --shard I/N``) is one Spark task:
the executor runs the ``stancelib`` binary on its shard and writes a shard library under
the work folder. The driver then runs ``stancelib merge``, which checks that the shards
belong to one build and writes a library equal, byte for byte, to a single-machine
``stancelib build`` of the same inputs with the same options.

Spark only schedules: it never reads the clips or the tables. Every path given here
(inputs, --work, --out) must therefore name the same files on the driver and on every
executor (a shared file system, or object storage mounted as one).

Local mode (one machine, Spark's own scheduler)::

    python3 pipelines/spark/stancelib_spark.py --master 'local[2]' \
        --stancelib target/release/stancelib --shards 8 --out out/spark-lib CLIPS_DIR

A cluster (see pipelines/spark/README.md)::

    spark-submit --master yarn --num-executors 16 --executor-cores 1 \
        --files /opt/stancelib/bin/stancelib \
        pipelines/spark/stancelib_spark.py --stancelib stancelib --shards 64 \
        --work /mnt/shared/stancelib/shards --out /mnt/shared/stancelib/lib /mnt/shared/bvh

Options after ``--`` go to every ``stancelib build`` unchanged (``--mass 70 --joints``...).
Exit code: that of the merge (0 every clip ok, 1 some clips failed), or 2 when a shard's
build failed (the shards are named) or the merge refused the shards.
"""

import argparse
import os
import shutil
import subprocess
import sys
import time

# Longest tail of a failed shard's stderr carried back to the driver, characters.
MAX_ERROR_CHARS = 2000


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("inputs", nargs="+", help="BVH files or folders (as for stancelib build)")
    p.add_argument("--out", required=True, help="the library folder to write")
    p.add_argument("--shards", type=int, default=0,
                   help="number of shards (default: Spark's default parallelism)")
    p.add_argument("--stancelib", default="stancelib",
                   help="the stancelib binary: a path, or a name found on PATH or shipped "
                        "with spark-submit --files")
    p.add_argument("--work", default=None,
                   help="folder for the shard libraries (default: .<out name>.shards beside --out)")
    p.add_argument("--threads", type=int, default=1,
                   help="worker threads of each shard's build (default 1: one per task)")
    p.add_argument("--master", default=None,
                   help="Spark master when not set by spark-submit (default local[*])")
    p.add_argument("--keep-shards", action="store_true",
                   help="keep the shard libraries after the merge")
    p.add_argument("--incremental", action="store_true",
                   help="rerun after a crash: each shard reuses the clips its library in "
                        "--work already holds (unchanged path, content and options) and "
                        "builds only the missing ones; the shards are kept")
    if "--" in argv:
        k = argv.index("--")
        args, extra = p.parse_args(argv[:k]), argv[k + 1:]
    else:
        args, extra = p.parse_args(argv), []
    args.build_args = extra
    return args


def resolve_binary(name):
    """The stancelib binary on this machine: as given, on PATH, or shipped with --files."""
    if os.path.sep in name and os.path.exists(name):
        return os.path.abspath(name)
    found = shutil.which(name)
    if found:
        return found
    try:
        from pyspark import SparkFiles
        shipped = SparkFiles.get(os.path.basename(name))
        if os.path.exists(shipped):
            os.chmod(shipped, 0o755)
            return shipped
    except Exception:  # not inside a Spark job, or nothing shipped
        pass
    return name


def shard_task(spec):
    """Runs on an executor: build one shard; returns (index, exit code, stderr tail)."""
    binary, inputs, work, index, count, threads, build_args = spec
    out = os.path.join(work, "shard-%d" % index)
    cmd = [resolve_binary(binary), "build", *inputs, "--out", out,
           "--shard", "%d/%d" % (index, count), "--threads", str(threads), *build_args]
    try:
        r = subprocess.run(cmd, capture_output=True, text=True)
    except OSError as e:
        return index, 2, "%s: %s" % (cmd[0], e)
    return index, r.returncode, r.stderr[-MAX_ERROR_CHARS:]


def stop_spark(spark):
    """Stop Spark; a failure to stop is a warning (the exit code is the merge's)."""
    try:
        spark.stop()
    except Exception as e:  # the JVM already gone, a gateway error: nothing left to do
        sys.stderr.write("stancelib-spark: warning: stopping Spark failed: %s\n" % e)


def report_phases(phases, count, master):
    """One line on stderr: where the wall time went (Spark start, shards, merge), s."""
    total = sum(t for _, t in phases)
    parts = ", ".join("%s %.2f s" % (name, t) for name, t in phases)
    sys.stderr.write("stancelib-spark: %s; total %.2f s (%d shards on %s)\n"
                     % (parts, total, count, master or "spark-submit's master"))


def main(argv):
    args = parse_args(argv)
    t0 = time.monotonic()
    os.environ.setdefault("PYSPARK_PYTHON", sys.executable)
    from pyspark.sql import SparkSession

    builder = SparkSession.builder.appName("stancelib-build")
    master = args.master or os.environ.get("MASTER")
    submitted = "--master" in os.environ.get("PYSPARK_SUBMIT_ARGS", "")
    if master or not submitted:
        master = master or "local[*]"
        builder = builder.master(master)
    if master and master.startswith("local"):
        # Local mode talks to itself only: keep the driver on the loopback interface.
        os.environ.setdefault("SPARK_LOCAL_IP", "127.0.0.1")
        builder = builder.config("spark.driver.host", "127.0.0.1") \
                         .config("spark.driver.bindAddress", "127.0.0.1") \
                         .config("spark.ui.enabled", "false")
    spark = builder.getOrCreate()
    sc = spark.sparkContext
    t_session = time.monotonic()
    count = args.shards or sc.defaultParallelism
    out = os.path.abspath(args.out)
    work = os.path.abspath(args.work or os.path.join(
        os.path.dirname(out), ".%s.shards" % os.path.basename(out)))
    os.makedirs(work, exist_ok=True)
    # As given: clips.parquet records each path as given (absolute paths on a cluster).
    inputs = list(args.inputs)
    build_args = args.build_args + (["--incremental"] if args.incremental else [])
    specs = [(args.stancelib, inputs, work, i, count, args.threads, build_args)
             for i in range(1, count + 1)]
    # One partition per shard: Spark runs each shard as one task, retrying lost executors.
    results = sc.parallelize(specs, count).map(shard_task).collect()
    t_shards = time.monotonic()
    # 0: every clip ok; 1: some clips failed (their rows say why); anything else: the build
    # of the shard did not finish.
    failed = sorted((i, code, err) for i, code, err in results if code not in (0, 1))
    if failed:
        stop_spark(spark)
        for i, code, err in failed:
            sys.stderr.write("shard %d/%d failed (exit %d):\n%s\n" % (i, count, code, err))
        sys.stderr.write("nothing merged; %s is unchanged\n" % out)
        return 2
    shards = [os.path.join(work, "shard-%d" % i) for i in range(1, count + 1)]
    # The merge needs no Spark: it runs while the JVM shuts down (about a second), and is
    # waited for whatever the stop does.
    cmd = [resolve_binary(args.stancelib), "merge", *shards, "--out", out]
    try:
        merge = subprocess.Popen(cmd)
    except OSError as e:
        stop_spark(spark)
        sys.stderr.write("%s: %s\nnothing merged; %s is unchanged\n" % (cmd[0], e, out))
        return 2
    try:
        stop_spark(spark)
    finally:
        t_stopped = time.monotonic()
        code = merge.wait()
    t_end = time.monotonic()
    report_phases([("Spark start", t_session - t0), ("shards", t_shards - t_session),
                   ("merge", t_end - t_shards)], count, master)
    sys.stderr.write("stancelib-spark: Spark stopped %.2f s into the merge\n"
                     % (t_stopped - t_shards))
    if code in (0, 1) and not (args.keep_shards or args.incremental):
        shutil.rmtree(work, ignore_errors=True)
    return code


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
