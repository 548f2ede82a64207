"""Runs that keep checkpoints in a sweep: each case's checkpoint in OUT/checkpoints (outside git: a
checkpoint is taken up only by the build that wrote it, on the machine that holds it), the bag of
a run's part before its restart kept beside the new part's, and a checkpoint its run refuses
removed so that the next resume runs the case afresh."""
import os


def checkpoint_path(out, name):
    """A run's checkpoint (outside git: OUT is no part of the checkout); a run stopped before its
    end is taken up from it by the next --resume."""
    return os.path.join(out, 'checkpoints', name + '.ckpt')


def keep_bag_part(out, name, bag=None):
    """Before a run is taken up from its checkpoint: the bag of its part so far becomes
    NAME.partK.bag (K = 1, 2, ...), so that the new part's bag does not replace it."""
    bag = bag or os.path.join(out, 'runs', name + '.bag')
    if not os.path.exists(bag):
        return None
    k = 1
    while os.path.exists(bag[:-4] + '.part%d.bag' % k):
        k += 1
    part = bag[:-4] + '.part%d.bag' % k
    os.replace(bag, part)
    return part


def refused_checkpoint(o, ck, line):
    """A run whose checkpoint was refused (written by another build, its inputs changed, damaged)
    fails at once, naming it: the checkpoint is removed, so that the next --resume runs it afresh."""
    if o.ok or not os.path.isfile(ck) or ck not in (o.error or ''):
        return False
    os.remove(ck)
    line('           ...    %-14s its checkpoint was refused and is removed: the next --resume runs it afresh'
         % o.name)
    return True
