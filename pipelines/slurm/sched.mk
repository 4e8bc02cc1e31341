# The scheduling layer of the pipelines: each stage of a bed (pack,
# settle-check, voidprof, ...) is run as `$(call sched,BED) CMD ARGS`, which
# is CMD itself with SCHEDULER=local (the default) and CMD as a Slurm job or
# job step with SCHEDULER=slurm (pipelines/slurm/run.sh; README "On a
# cluster"). Included by every pipelines/*.mk; reads $(OUT) at use.
SCHEDULER ?= local
# Where each bed's log goes (every Slurm leg of every stage appends to it).
SLURM_LOGS ?= $(OUT)/slurm
# auto: job steps (srun) inside an allocation, else batch jobs (sbatch --wait).
SLURM_MODE ?= auto
# More sbatch/srun options, e.g. SLURM_ARGS="--partition=long --account=me".
SLURM_ARGS ?=
# The longest time limit asked for (minutes; a longer bed is requeued and
# resumed), the other stages' limit, the warning before the limit (s), and the
# most times a pack job requeues itself.
SLURM_MAX_TIME ?= 1440
SLURM_SHORT_TIME ?= 60
SLURM_GRACE ?= 300
SLURM_REQUEUES ?= 10
# Threads of each bed's engine (pack --threads): one, so that `make -jN` runs N beds on N
# cores without oversubscribing them; THREADS=k gives each bed k threads (and, under Slurm,
# k CPUs).
THREADS ?= 1
SLURM_CPUS ?= $(THREADS)

SCHED_RUN := $(patsubst %/,%,$(dir $(lastword $(MAKEFILE_LIST))))/run.sh
ifeq ($(SCHEDULER),slurm)
sched = sh $(SCHED_RUN) --name $(1) --log $(SLURM_LOGS)/$(1).log --mode $(SLURM_MODE) --cpus $(SLURM_CPUS) \
  --max-time $(SLURM_MAX_TIME) --short-time $(SLURM_SHORT_TIME) --grace $(SLURM_GRACE) \
  --requeues $(SLURM_REQUEUES) --args '$(SLURM_ARGS)' --
else ifeq ($(SCHEDULER),local)
sched =
else
$(error SCHEDULER=$(SCHEDULER): give local or slurm)
endif
