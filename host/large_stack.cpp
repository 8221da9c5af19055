#include "host/large_stack.h"

#include <pthread.h>

namespace psys::host {

namespace {

struct Job {
    const std::function<int()>* body;
    int result = 0;
};

void* run(void* p) {
    auto* job = static_cast<Job*>(p);
    job->result = (*job->body)();
    return nullptr;
}

}  // namespace

int runWithLargeStack(const std::function<int()>& body, size_t bytes) {
    Job job{&body};
    pthread_attr_t attr;
    pthread_t thread;
    bool made = pthread_attr_init(&attr) == 0 && pthread_attr_setstacksize(&attr, bytes) == 0 &&
                pthread_create(&thread, &attr, run, &job) == 0;
    pthread_attr_destroy(&attr);
    if (!made) return body();
    pthread_join(thread, nullptr);
    return job.result;
}

}  // namespace psys::host
