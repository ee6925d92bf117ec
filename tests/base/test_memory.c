/*
 * test_memory.c -- the system's memory limit (src/base/memory.c): the
 * smallest of MemAvailable (else 3/4 of physical memory), the cgroup's room (v2 memory.max less
 * memory.current, v1 memory.limit_in_bytes less memory.usage_in_bytes, in
 * the process's own cgroup folder or at the root) and the address-space
 * room, read from a fake /proc and /sys tree in a scratch folder, less the
 * safety margin; and the real system's answer, which must be some positive
 * size (test_auto_tiling.sh runs the real one under ulimit -v).
 */
#include "base/internal.h"
#include "tt_test.h"

#include <sys/stat.h>
#include <unistd.h>

static char root[256];

static void put(const char *rel, const char *text)
{
  char path[512], cmd[600];
  snprintf(path, sizeof path, "%s/%s", root, rel);
  snprintf(cmd, sizeof cmd, "mkdir -p \"$(dirname '%s')\"", path);
  if (system(cmd) != 0)
    TT_FAIL_("cannot make the folder of %s", path);
  FILE *f = fopen(path, "w");
  if (!f) {
    TT_FAIL_("cannot write %s", path);
    return;
  }
  fputs(text, f);
  fclose(f);
}

/* The limit of a room: less an eighth and 32 MiB, half under 64 MiB. */
static uint64_t margin(uint64_t room)
{
  const uint64_t mib = (uint64_t)1 << 20;
  return room < 64 * mib ? (room / 2 ? room / 2 : 1)
                         : room - room / 8 - 32 * mib;
}

static void clear(void)
{
  char cmd[600];
  snprintf(cmd, sizeof cmd, "rm -rf '%s'/proc '%s'/sys", root, root);
  if (system(cmd) != 0)
    TT_FAIL_("cannot clear %s", root);
}

int main(void)
{
  const char *src = NULL;
  const uint64_t G = (uint64_t)1 << 30;
  snprintf(root, sizeof root, "/tmp/tt_test_memory.%ld", (long)getpid());
  mkdir(root, 0700);

  /* nothing but physical memory */
  clear();
  CHECK_INT_EQ(tt__memory_limit_at(root, 16 * G, 0, 0, &src),
               margin(12 * G));
  CHECK(strstr(src, "physical") != NULL);
  CHECK_INT_EQ(tt__memory_limit_at(root, 0, 0, 0, &src), SIZE_MAX);

  /* cgroup v2 in the process's own folder: max less current */
  put("proc/self/cgroup", "0::/job/42\n");
  put("sys/fs/cgroup/job/42/memory.max", "2147483648\n");
  put("sys/fs/cgroup/job/42/memory.current", "536870912\n");
  CHECK_INT_EQ(tt__memory_limit_at(root, 16 * G, 0, 0, &src),
               margin((size_t)3 << 29));
  CHECK(strstr(src, "memory.max") != NULL);
  /* "max" is no limit */
  put("sys/fs/cgroup/job/42/memory.max", "max\n");
  CHECK_INT_EQ(tt__memory_limit_at(root, 16 * G, 0, 0, &src),
               margin(12 * G));
  /* at the root of a container's namespace */
  clear();
  put("proc/self/cgroup", "0::/\n");
  put("sys/fs/cgroup/memory.max", "1073741824\n");
  CHECK_INT_EQ(tt__memory_limit_at(root, 16 * G, 0, 0, &src),
               margin(G));

  /* cgroup v1 */
  clear();
  put("proc/self/cgroup", "12:cpu,cpuacct:/a\n4:memory:/a\n");
  put("sys/fs/cgroup/memory/a/memory.limit_in_bytes", "3221225472\n");
  put("sys/fs/cgroup/memory/a/memory.usage_in_bytes", "1073741824\n");
  CHECK_INT_EQ(tt__memory_limit_at(root, 16 * G, 0, 0, &src),
               margin(2 * G));
  CHECK(strstr(src, "limit_in_bytes") != NULL);
  /* v1's "no limit" is a huge number: physical memory decides */
  put("sys/fs/cgroup/memory/a/memory.limit_in_bytes",
      "9223372036854771712\n");
  CHECK_INT_EQ(tt__memory_limit_at(root, 16 * G, 0, 0, &src),
               margin(12 * G));

  /* ulimit -v: the room left under it, smallest of all */
  CHECK_INT_EQ(tt__memory_limit_at(root, 16 * G, G, G / 4, &src),
               margin(3 * G / 4));
  CHECK(strstr(src, "ulimit -v") != NULL);
  /* already past it: one byte of room, never zero ("no limit") */
  CHECK_INT_EQ(tt__memory_limit_at(root, 16 * G, G, 2 * G, &src),
               margin(1));

  /* MemAvailable, when /proc/meminfo has it, before physical memory */
  clear();
  put("proc/meminfo", "MemTotal:       16384 kB\nMemFree:  1 kB\n"
                      "MemAvailable:    2097152 kB\n");
  CHECK_INT_EQ(tt__memory_limit_at(root, 16 * G, 0, 0, &src), margin(2 * G));
  CHECK(strstr(src, "MemAvailable") != NULL);
  /* a tiny room: half of it */
  CHECK_INT_EQ(tt__memory_limit_at(root, 16 * G, G, G - (40 << 20), &src),
               20 << 20);

  /* the real system */
  size_t real = tt_memory_limit(&src);
  CHECK(real > 0);
  CHECK(src != NULL && *src);

  char buf[32];
  CHECK_STR_EQ(tt__format_bytes(buf, sizeof buf, 12), "12 bytes");
  CHECK_STR_EQ(tt__format_bytes(buf, sizeof buf, 3 * G / 2), "1.5 GiB");

  clear();
  rmdir(root);
  TT_TEST_DONE();
}
