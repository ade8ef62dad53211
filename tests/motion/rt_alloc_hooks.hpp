// What this executable's own operator new and delete and its pthread mutex, rwlock,
// spinlock and semaphore waits (rt_alloc_hooks.cpp, forwarding to the C library's) count while
// `in_period` is set on the calling thread. Sanitizer runtimes bring their own operator new
// and intercept the locks: there nothing is counted and CNCD_RT_ALLOC_SANITIZED is 1.
#pragma once

#include <atomic>

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define CNCD_RT_ALLOC_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define CNCD_RT_ALLOC_SANITIZED 1
#endif
#endif
#ifndef CNCD_RT_ALLOC_SANITIZED
#define CNCD_RT_ALLOC_SANITIZED 0
#endif

namespace cncd::test::rt_hooks {

extern thread_local bool in_period;
extern std::atomic<long> period_allocs;
extern std::atomic<long> period_frees;
extern std::atomic<long> period_locks;

}  // namespace cncd::test::rt_hooks
