// The counting operator new and delete and lock hooks of rt_alloc_hooks.hpp.
#include "rt_alloc_hooks.hpp"

#include <dlfcn.h>
#include <pthread.h>
#include <semaphore.h>

#include <cstdlib>
#include <new>

namespace cncd::test::rt_hooks {

thread_local bool in_period = false;
std::atomic<long> period_allocs{0};
std::atomic<long> period_frees{0};
std::atomic<long> period_locks{0};

}  // namespace cncd::test::rt_hooks

#if !CNCD_RT_ALLOC_SANITIZED
namespace {

void* counted_alloc(std::size_t size) {
  if (cncd::test::rt_hooks::in_period)
    cncd::test::rt_hooks::period_allocs.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(size == 0 ? 1 : size);
}

void* counted_alloc(std::size_t size, std::align_val_t align) {
  if (cncd::test::rt_hooks::in_period)
    cncd::test::rt_hooks::period_allocs.fetch_add(1, std::memory_order_relaxed);
  const auto a = static_cast<std::size_t>(align);
  return std::aligned_alloc(a, (size + a - 1) / a * a);
}

void counted_free(void* p) noexcept {
  if (p != nullptr && cncd::test::rt_hooks::in_period)
    cncd::test::rt_hooks::period_frees.fetch_add(1, std::memory_order_relaxed);
  std::free(p);
}

}  // namespace

void* operator new(std::size_t size) {
  if (void* p = counted_alloc(size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) {
  if (void* p = counted_alloc(size)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  return counted_alloc(size);
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  return counted_alloc(size);
}
void* operator new(std::size_t size, std::align_val_t align) {
  if (void* p = counted_alloc(size, align)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size, std::align_val_t align) {
  if (void* p = counted_alloc(size, align)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  counted_free(p);
}
void operator delete[](void* p) noexcept {
  counted_free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  counted_free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  counted_free(p);
}
void operator delete(void* p, std::align_val_t) noexcept {
  counted_free(p);
}
void operator delete[](void* p, std::align_val_t) noexcept {
  counted_free(p);
}
void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
  counted_free(p);
}
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept {
  counted_free(p);
}

namespace {

// The C library's definition of `name`, looked up once.
void* next_symbol(std::atomic<void*>& cache, const char* name) noexcept {
  void* symbol = cache.load(std::memory_order_acquire);
  if (symbol == nullptr) {
    symbol = dlsym(RTLD_NEXT, name);
    cache.store(symbol, std::memory_order_release);
  }
  return symbol;
}

}  // namespace

// Each counts a call made in the servo period, then does what the C library does. Condition
// waits need a mutex, which is counted already.
#define CNCD_COUNTED_LOCK(name, params, args, spec)                               \
  extern "C" int name params spec {                                               \
    if (cncd::test::rt_hooks::in_period)                                          \
      cncd::test::rt_hooks::period_locks.fetch_add(1, std::memory_order_relaxed); \
    static std::atomic<void*> next{nullptr};                                      \
    return reinterpret_cast<decltype(&name)>(next_symbol(next, #name)) args;      \
  }
CNCD_COUNTED_LOCK(pthread_mutex_lock, (pthread_mutex_t * m), (m), noexcept)
CNCD_COUNTED_LOCK(pthread_mutex_trylock, (pthread_mutex_t * m), (m), noexcept)
CNCD_COUNTED_LOCK(pthread_mutex_timedlock,
                  (pthread_mutex_t* __restrict m, const timespec* __restrict t), (m, t), noexcept)
CNCD_COUNTED_LOCK(pthread_mutex_clocklock,
                  (pthread_mutex_t* __restrict m, clockid_t c, const timespec* __restrict t),
                  (m, c, t), noexcept)
CNCD_COUNTED_LOCK(pthread_rwlock_rdlock, (pthread_rwlock_t * l), (l), noexcept)
CNCD_COUNTED_LOCK(pthread_rwlock_wrlock, (pthread_rwlock_t * l), (l), noexcept)
CNCD_COUNTED_LOCK(pthread_rwlock_tryrdlock, (pthread_rwlock_t * l), (l), noexcept)
CNCD_COUNTED_LOCK(pthread_rwlock_trywrlock, (pthread_rwlock_t * l), (l), noexcept)
CNCD_COUNTED_LOCK(pthread_rwlock_timedrdlock,
                  (pthread_rwlock_t* __restrict l, const timespec* __restrict t), (l, t), noexcept)
CNCD_COUNTED_LOCK(pthread_rwlock_timedwrlock,
                  (pthread_rwlock_t* __restrict l, const timespec* __restrict t), (l, t), noexcept)
CNCD_COUNTED_LOCK(pthread_spin_lock, (pthread_spinlock_t * l), (l), noexcept)
CNCD_COUNTED_LOCK(sem_wait, (sem_t * s), (s), )
CNCD_COUNTED_LOCK(sem_trywait, (sem_t * s), (s), noexcept)
CNCD_COUNTED_LOCK(sem_timedwait, (sem_t* __restrict s, const timespec* __restrict t), (s, t), )
#undef CNCD_COUNTED_LOCK
#endif
