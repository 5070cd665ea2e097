#!/usr/bin/env python3
"""Structural check of deploy/k8s/render-job.yaml (Kubernetes cannot run in
CI): it parses, holds a ReadWriteMany claim, an Indexed render Job whose
`--part auto/N` matches its completions, and a merge Job that waits for N
parts in the folder the render Job writes to, both mounting the claim at the
same path. Prints what is wrong and exits 1, or prints a summary."""

import re
import sys

import yaml

path = sys.argv[1] if len(sys.argv) > 1 else "deploy/k8s/render-job.yaml"
with open(path, encoding="utf-8") as f:
    documents = [d for d in yaml.safe_load_all(f) if d]

problems = []


def need(condition, message):
    if not condition:
        problems.append(message)
    return condition


def by_kind(kind, name=None):
    found = [d for d in documents if d.get("kind") == kind and (name is None or d["metadata"]["name"] == name)]
    return found[0] if found else None


claim = by_kind("PersistentVolumeClaim")
render = by_kind("Job", "prism-render")
merge = by_kind("Job", "prism-merge")
need(claim is not None, "no PersistentVolumeClaim")
need(render is not None, "no Job named prism-render")
need(merge is not None, "no Job named prism-merge")
if claim and render and merge:
    need("ReadWriteMany" in claim["spec"]["accessModes"], "the claim is not ReadWriteMany: pods on several nodes must share it")
    for job in (render, merge):
        need(job.get("apiVersion") == "batch/v1", f"{job['metadata']['name']}: apiVersion is not batch/v1")
        pod = job["spec"]["template"]["spec"]
        need(pod.get("restartPolicy") in ("Never", "OnFailure"), f"{job['metadata']['name']}: a Job's pods need restartPolicy Never or OnFailure")
        volumes = {v["name"]: v for v in pod.get("volumes", [])}
        for container in pod["containers"]:
            for mount in container.get("volumeMounts", []):
                volume = volumes.get(mount["name"])
                need(volume is not None, f"{job['metadata']['name']}: mount {mount['name']} has no volume")
                if volume:
                    need(volume.get("persistentVolumeClaim", {}).get("claimName") == claim["metadata"]["name"],
                         f"{job['metadata']['name']}: volume {mount['name']} is not the shared claim")
                    need(mount["mountPath"] == "/shared", f"{job['metadata']['name']}: the claim is mounted at {mount['mountPath']}, not /shared")
    spec = render["spec"]
    need(spec.get("completionMode") == "Indexed", "the render Job is not an Indexed Job (JOB_COMPLETION_INDEX would be unset)")
    completions = spec.get("completions")
    need(isinstance(completions, int) and completions > 0, "the render Job has no completion count")
    render_script = " ".join(render["spec"]["template"]["spec"]["containers"][0]["args"])
    part = re.search(r"--part auto/(\d+)", render_script)
    if need(part, "the render Job does not run `prism render --part auto/N`"):
        need(int(part.group(1)) == completions, f"--part auto/{part.group(1)} but the Job has {completions} completions")
    output = re.search(r"-o (\S+)/part-\$\{JOB_COMPLETION_INDEX\}\.film", render_script)
    if need(output, "the render Job does not write part-${JOB_COMPLETION_INDEX}.film"):
        parts_folder = output.group(1)
        merge_container = merge["spec"]["template"]["spec"]["containers"][0]
        merge_script = " ".join(merge_container["args"])
        need(f"prism merge {parts_folder}/part-*.film" in merge_script, f"the merge Job does not merge {parts_folder}/part-*.film")
        env = {e["name"]: e.get("value") for e in merge_container.get("env", [])}
        need(env.get("PARTS") == str(completions), f"the merge Job waits for {env.get('PARTS')} parts, the render Job makes {completions}")
    need("activeDeadlineSeconds" in merge["spec"], "the merge Job has no deadline: it would wait forever for a missing part")

if problems:
    for problem in problems:
        print(f"{path}: {problem}", file=sys.stderr)
    sys.exit(1)
print(f"{path}: a claim, an Indexed Job of {completions} parts and a merge Job, consistent")
