/*
 * memory.c -- how much memory a run may use: the system's limits, read once
 * per run, and the byte counts and sizes for the messages that refuse more.
 *
 * A process can be stopped short of physical memory by its control group
 * (cgroup v2 memory.max, v1 memory.limit_in_bytes: the kernel's OOM killer
 * ends it, no malloc ever fails) or by its address-space limit (ulimit -v,
 * RLIMIT_AS: malloc fails), and by what the machine has free. The room is
 * the smallest of the physical memory available for new work (MemAvailable
 * of /proc/meminfo: free memory and the page cache that can be dropped;
 * without it, 3/4 of physical memory), the cgroup's limit less what the
 * group already uses, and the address-space limit less what the process
 * has already mapped (libraries, thread stacks). The limit is that room
 * less a safety margin (MEMORY_MARGIN: an eighth of it and 32 MiB, or half
 * of a room under 64 MiB) for what no run counts -- GDAL's block cache, the
 * output driver's buffers, the arenas and stacks of the worker threads --
 * so that a refusal or the choice of tiles comes with a size and a reason
 * instead of a kill.
 *
 * Linux files are read when present; elsewhere only sysconf and getrlimit
 * answer. Nothing is cached: callers ask once per run.
 *
 * Part of src/base/, the base stage: the context and its errors, grids, exact
 * predicates, the heap, threads, memory limits.
 */
#include "base/internal.h"

#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

/* The room less the safety margin (see the top of the file). */
static uint64_t less_margin(uint64_t room)
{
  const uint64_t mib = (uint64_t)1 << 20;
  if (room == UINT64_MAX)
    return room;
  if (room < 64 * mib)
    return room / 2 ? room / 2 : 1;
  return room - room / 8 - 32 * mib;
}

/* MemAvailable of a /proc/meminfo, in bytes; 0 when absent. */
static uint64_t mem_available(const char *path)
{
  FILE *f = fopen(path, "r");
  if (!f)
    return 0;
  char line[256];
  unsigned long long kb = 0;
  int found = 0;
  while (!found && fgets(line, sizeof line, f))
    found = sscanf(line, "MemAvailable: %llu kB", &kb) == 1;
  fclose(f);
  return found ? (uint64_t)kb * 1024 : 0;
}

/* Reads the first unsigned number of a file; 0 when absent, unreadable or
 * "max" (cgroup v2's word for no limit). */
static uint64_t read_u64_file(const char *path)
{
  FILE *f = fopen(path, "r");
  if (!f)
    return 0;
  unsigned long long v = 0;
  int ok = fscanf(f, "%llu", &v) == 1;
  fclose(f);
  return ok ? (uint64_t)v : 0;
}

/* The process's own cgroup folder for a hierarchy: the path after the
 * controller field of /proc/self/cgroup ("0::/a/b" for v2, "4:memory:/a/b"
 * for v1); "" when it says nothing (then the root files are read). */
static void cgroup_path(const char *proc_cgroup, int v2, char *out,
                        size_t size)
{
  out[0] = '\0';
  FILE *f = fopen(proc_cgroup, "r");
  if (!f)
    return;
  char line[1024];
  while (fgets(line, sizeof line, f)) {
    char *c1 = strchr(line, ':');
    char *c2 = c1 ? strchr(c1 + 1, ':') : NULL;
    if (!c2)
      continue;
    *c2 = '\0';
    const char *ctrl = c1 + 1;
    int match = v2 ? *ctrl == '\0' && strncmp(line, "0:", 2) == 0
                   : strstr(ctrl, "memory") != NULL;
    if (!match)
      continue;
    char *p = c2 + 1;
    p[strcspn(p, "\n")] = '\0';
    if (strcmp(p, "/") != 0)
      snprintf(out, size, "%s", p);
    break;
  }
  fclose(f);
}

/* The cgroup's limit less its current use, in bytes; 0 when none. */
static uint64_t cgroup_room(const char *root, const char **out_source)
{
  char proc[512], own[600], path[1400];
  snprintf(proc, sizeof proc, "%s/proc/self/cgroup", root);
  /* v2: one hierarchy, memory.max and memory.current */
  cgroup_path(proc, 1, own, sizeof own);
  for (int pass = 0; pass < 2; pass++) {
    snprintf(path, sizeof path, "%s/sys/fs/cgroup%s/memory.max", root,
             pass ? "" : own);
    uint64_t max = read_u64_file(path);
    if (max) {
      snprintf(path, sizeof path, "%s/sys/fs/cgroup%s/memory.current", root,
               pass ? "" : own);
      uint64_t cur = read_u64_file(path);
      *out_source = "the room left under the cgroup's memory.max";
      return max > cur ? max - cur : 1;
    }
    if (!own[0])
      break;
  }
  /* v1: the memory controller's own hierarchy; "no limit" is a huge
   * number there (PAGE_COUNTER_MAX pages), which the min below ignores */
  cgroup_path(proc, 0, own, sizeof own);
  for (int pass = 0; pass < 2; pass++) {
    snprintf(path, sizeof path, "%s/sys/fs/cgroup/memory%s/"
             "memory.limit_in_bytes", root, pass ? "" : own);
    uint64_t max = read_u64_file(path);
    if (max) {
      snprintf(path, sizeof path, "%s/sys/fs/cgroup/memory%s/"
               "memory.usage_in_bytes", root, pass ? "" : own);
      uint64_t cur = read_u64_file(path);
      *out_source = "the room left under the cgroup's memory.limit_in_bytes";
      return max > cur ? max - cur : 1;
    }
    if (!own[0])
      break;
  }
  return 0;
}

size_t tt__memory_limit_at(const char *root, uint64_t phys_bytes,
                           uint64_t as_limit, uint64_t as_used,
                           const char **out_source)
{
  uint64_t best = UINT64_MAX;
  const char *source = "no limit known";
  char meminfo[512];
  snprintf(meminfo, sizeof meminfo, "%s/proc/meminfo", root);
  uint64_t avail = mem_available(meminfo);
  if (avail) {
    best = avail;
    source = "the physical memory available (MemAvailable)";
  } else if (phys_bytes) {
    best = phys_bytes / 4 * 3;
    source = "3/4 of this machine's physical memory";
  }
  const char *cg_source = NULL;
  uint64_t cg = cgroup_room(root, &cg_source);
  if (cg && cg < best) {
    best = cg;
    source = cg_source;
  }
  if (as_limit) {
    uint64_t room = as_limit > as_used ? as_limit - as_used : 1;
    if (room < best) {
      best = room;
      source = "the room left under ulimit -v (RLIMIT_AS)";
    }
  }
  if (out_source)
    *out_source = source;
  best = less_margin(best);
  return best >= (uint64_t)SIZE_MAX ? SIZE_MAX : (size_t)best;
}

size_t tt_memory_limit(const char **out_source)
{
  uint64_t phys = 0, as_limit = 0, as_used = 0;
  long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  if (pages > 0 && page > 0)
    phys = (uint64_t)pages * (uint64_t)page;
  struct rlimit rl;
  if (getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY) {
    as_limit = (uint64_t)rl.rlim_cur;
    /* what is mapped already counts against it: /proc/self/statm's first
     * field, in pages */
    uint64_t vm_pages = read_u64_file("/proc/self/statm");
    if (page > 0)
      as_used = vm_pages * (uint64_t)page;
  }
  return tt__memory_limit_at("", phys, as_limit, as_used, out_source);
}

const char *tt__format_bytes(char *buf, size_t size, uint64_t bytes)
{
  static const char *const units[] = {"bytes", "KiB", "MiB", "GiB", "TiB",
                                      "PiB", "EiB"};
  double v = (double)bytes;
  int u = 0;
  while (v >= 1024.0 && u < 6) {
    v /= 1024.0;
    u++;
  }
  if (u == 0)
    snprintf(buf, size, "%llu bytes", (unsigned long long)bytes);
  else
    snprintf(buf, size, "%.1f %s", v, units[u]);
  return buf;
}
