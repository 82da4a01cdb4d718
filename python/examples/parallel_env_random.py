# %% [markdown]
# # Several agents at once: random actions in `mergesim.parallel_env`
#
# Every connected, planner-driven vehicle of the urgent merge (the ego and the obstacle) is an
# agent; each step every live agent sends a random [target_speed_mps, lateral_offset_m], and the
# environment is reset when no agent is left. Prints how many steps it ran, how many episodes
# ended, how each agent's episodes ended, and the steps per second.
# Run as a script (`python examples/parallel_env_random.py [STEPS] [SCENARIO]`, 1,000 steps of
# the urgent merge by default) or cell by cell.

# %%
import sys
import time
from collections import Counter

import mergesim

STEPS = int(sys.argv[1]) if len(sys.argv) > 1 else 1000
SCENARIO = sys.argv[2] if len(sys.argv) > 2 else "urgent_merge"

env = mergesim.parallel_env(SCENARIO)
for i, agent in enumerate(env.possible_agents):
    env.action_space(agent).seed(i)
print(f"{SCENARIO}: agents {', '.join(env.possible_agents)}")

# %%
endings: Counter = Counter()
episodes = 0
observations, infos = env.reset(seed=0)
started = time.perf_counter()
for _ in range(STEPS):
    actions = {agent: env.action_space(agent).sample() for agent in env.agents}
    observations, rewards, terminations, truncations, infos = env.step(actions)
    for agent, info in infos.items():
        if terminations[agent]:
            reason = next(
                (k for k in ("collision", "road_edge", "end_of_road", "error") if info.get(k)),
                "terminated",
            )
            endings[(agent, reason)] += 1
        elif truncations[agent]:
            endings[(agent, "truncated")] += 1
    if not env.agents:
        episodes += 1
        observations, infos = env.reset()
elapsed_s = time.perf_counter() - started

# %%
print(f"{STEPS} steps, {episodes} episodes ended")
for (agent, reason), count in sorted(endings.items()):
    print(f"  {agent}: {reason} × {count}")
print(f"{STEPS / elapsed_s:.0f} steps/s")
